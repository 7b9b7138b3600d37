// The scenario's random numbers: one generator per scenario, seeded from `seed`, with its
// own distribution code so that the same seed draws the same numbers with every compiler
// and standard library (std::normal_distribution's output is not specified and differs
// between libstdc++ and libc++). No allocation, no global state.
//
//   SplitMix64 (Steele, Lea, Flood 2014) expands the 64-bit seed into the state;
//   xoshiro256** (Blackman, Vigna 2018) draws; uniform() takes the top 53 bits;
//   normal() is Marsaglia and Tsang's ziggurat (2000) in Doornik's form (2005): 128
//   layers of equal area under the density; about 99 % of draws take one 64-bit number,
//   one table lookup and one multiply (the top 53 bits make the sign and the position, 7
//   low bits the layer), the rest fall in a wedge (two exp) or the tail beyond 3.44 (log).
//   A scenario draws millions of normals a second at plant scale (random_walk, lag
//   noise, noise()): the polar method's log and sqrt per pair were 7 % of a tick.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>

namespace fins::scenario {

class Random {
  public:
    explicit Random(std::uint64_t seed = 0) noexcept { reseed(seed); }

    void reseed(std::uint64_t seed) noexcept {
        std::uint64_t x = seed;
        for (auto& word : state_)
            word = splitmix64(x);
    }

    std::uint64_t next() noexcept {
        const std::uint64_t result = rotl(state_[1] * 5, 7) * 9;
        const std::uint64_t t = state_[1] << 17;
        state_[2] ^= state_[0];
        state_[3] ^= state_[1];
        state_[1] ^= state_[2];
        state_[0] ^= state_[3];
        state_[2] ^= t;
        state_[3] = rotl(state_[3], 45);
        return result;
    }

    // [0, 1), 53 random bits.
    double uniform() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

    // Mean 0, standard deviation 1.
    double normal() noexcept {
        const Ziggurat& z = ziggurat();
        // Bounded: a try is rejected with a chance of about 1.2 %, so 64 misses in a row
        // have a chance below 1e-120.
        for (int attempt = 0; attempt < 64; ++attempt) {
            const std::uint64_t bits = next();
            const double u = 2.0 * (static_cast<double>(bits >> 11) * 0x1.0p-53) - 1.0;
            const unsigned layer = static_cast<unsigned>(bits & (Ziggurat::layers - 1));
            // Inside the layer's rectangle, under the density for sure.
            if (std::fabs(u) < z.ratio[layer]) return u * z.x[layer];
            // The bottom layer's part beyond the rectangle is the tail, x > r.
            if (layer == 0) return tail(u < 0);
            // A wedge: under the density with the chance the two edges' heights give.
            const double x = u * z.x[layer];
            const double f0 = std::exp(-0.5 * (z.x[layer] * z.x[layer] - x * x));
            const double f1 = std::exp(-0.5 * (z.x[layer + 1] * z.x[layer + 1] - x * x));
            if (f1 + uniform() * (f0 - f1) < 1.0) return x;
        }
        return 0.0;
    }

  private:
    // The layers' right edges x[0..128] (x[0]: the bottom layer's width as if its area
    // were a rectangle, x[1] = r, x[128] = 0) and ratio[i] = x[i+1] / x[i], the part of a
    // layer inside the next one's rectangle. r and the common area v are Marsaglia and
    // Tsang's for 128 layers; the edges follow from them with exp, log and sqrt, once.
    struct Ziggurat {
        static constexpr unsigned layers = 128;
        static constexpr double r = 3.442619855899;
        static constexpr double v = 9.91256303526217e-3;
        std::array<double, layers + 1> x{};
        std::array<double, layers> ratio{};
        Ziggurat() noexcept {
            double f = std::exp(-0.5 * r * r);
            x[0] = v / f;
            x[1] = r;
            x[layers] = 0.0;
            for (unsigned i = 2; i < layers; ++i) {
                x[i] = std::sqrt(-2.0 * std::log(v / x[i - 1] + f));
                f = std::exp(-0.5 * x[i] * x[i]);
            }
            for (unsigned i = 0; i < layers; ++i)
                ratio[i] = x[i + 1] / x[i];
        }
    };
    static const Ziggurat& ziggurat() noexcept {
        static const Ziggurat table;
        return table;
    }
    // A normal beyond r (Marsaglia 1964), on the side `negative` says; bounded as above
    // (a try succeeds with a chance above 0.9).
    double tail(bool negative) noexcept {
        for (int attempt = 0; attempt < 64; ++attempt) {
            // 1 - uniform() is in (0, 1]: no log(0).
            const double x = std::log(1.0 - uniform()) / Ziggurat::r;
            const double y = std::log(1.0 - uniform());
            if (-2.0 * y >= x * x) return negative ? x - Ziggurat::r : Ziggurat::r - x;
        }
        return negative ? -Ziggurat::r : Ziggurat::r;
    }

    static std::uint64_t rotl(std::uint64_t x, int k) noexcept {
        return (x << k) | (x >> (64 - k));
    }
    static std::uint64_t splitmix64(std::uint64_t& x) noexcept {
        std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
        return z ^ (z >> 31);
    }

    std::array<std::uint64_t, 4> state_{};
};

}  // namespace fins::scenario
