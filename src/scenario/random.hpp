// The scenario's random numbers: one generator per scenario, seeded from `seed`, with its
// own distribution code so that the same seed draws the same numbers with every compiler
// and standard library (std::normal_distribution's output is not specified and differs
// between libstdc++ and libc++). No allocation, no global state.
//
//   SplitMix64 (Steele, Lea, Flood 2014) expands the 64-bit seed into the state;
//   xoshiro256** (Blackman, Vigna 2018) draws; uniform() takes the top 53 bits;
//   normal() is Marsaglia's polar method (1964), keeping the second value of each pair
//   for the next call.
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
        spare_valid_ = false;
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
        if (spare_valid_) {
            spare_valid_ = false;
            return spare_;
        }
        // A point drawn uniformly in the unit disc (about 1.27 tries; bounded, and the
        // chance of 64 misses is below 1e-42), then scaled: two normals from one log and
        // one sqrt, with no sin/cos.
        for (int attempt = 0; attempt < 64; ++attempt) {
            const double u = 2.0 * uniform() - 1.0;
            const double v = 2.0 * uniform() - 1.0;
            const double s = u * u + v * v;
            if (s >= 1.0 || s == 0.0) continue;
            const double scale = std::sqrt(-2.0 * std::log(s) / s);
            spare_ = v * scale;
            spare_valid_ = true;
            return u * scale;
        }
        return 0.0;
    }

  private:
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
    double spare_ = 0.0;
    bool spare_valid_ = false;
};

}  // namespace fins::scenario
