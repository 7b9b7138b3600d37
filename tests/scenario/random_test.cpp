// The scenario's own random numbers (src/scenario/random.hpp): the same seed draws the
// same numbers, and normal() has the normal distribution's moments and tails, through its
// rectangles, its wedges and its tail beyond r alike.
#include "scenario/random.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace fins::scenario {
namespace {

TEST(ScenarioRandom, TheSameSeedDrawsTheSameNumbersAnotherSeedOthers) {
    Random a(42), b(42), c(43);
    bool differs = false;
    for (int i = 0; i < 1000; ++i) {
        const double x = a.normal(), y = b.normal(), z = c.normal();
        EXPECT_EQ(x, y);
        differs = differs || x != z;
        EXPECT_EQ(a.uniform(), b.uniform());
    }
    EXPECT_TRUE(differs);
    // reseed starts the sequence again.
    a.reseed(7);
    b.reseed(7);
    EXPECT_EQ(a.next(), b.next());
}

TEST(ScenarioRandom, UniformIsInTheHalfOpenUnitInterval) {
    Random r(1);
    double low = 1, high = 0, sum = 0;
    constexpr int n = 200000;
    for (int i = 0; i < n; ++i) {
        const double u = r.uniform();
        ASSERT_GE(u, 0.0);
        ASSERT_LT(u, 1.0);
        low = std::min(low, u);
        high = std::max(high, u);
        sum += u;
    }
    EXPECT_LT(low, 1e-4);
    EXPECT_GT(high, 1 - 1e-4);
    EXPECT_NEAR(sum / n, 0.5, 0.005);
}

TEST(ScenarioRandom, NormalHasTheMomentsAndTailsOfTheStandardNormal) {
    Random r(2026);
    constexpr std::size_t n = 1'000'000;
    double sum = 0, squares = 0, fourth = 0;
    std::size_t beyond_1 = 0, beyond_2 = 0, beyond_r = 0, positive_tail = 0;
    // 32 bins of width 0.25 over [-4, 4): every layer's rectangle and wedge lands in some.
    std::vector<std::size_t> bins(32, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const double x = r.normal();
        ASSERT_TRUE(std::isfinite(x));
        sum += x;
        squares += x * x;
        fourth += x * x * x * x;
        if (x >= -4.0 && x < 4.0) ++bins[static_cast<std::size_t>((x + 4.0) * 4.0)];
        const double a = std::fabs(x);
        beyond_1 += a > 1.0;
        beyond_2 += a > 2.0;
        if (a > 3.442619855899) {  // the ziggurat's tail
            ++beyond_r;
            positive_tail += x > 0;
        }
    }
    const double mean = sum / n;
    const double variance = squares / n - mean * mean;
    // Standard errors at n = 1e6: mean 0.001, variance 0.0014, kurtosis 0.0025.
    EXPECT_NEAR(mean, 0.0, 0.005);
    EXPECT_NEAR(variance, 1.0, 0.007);
    EXPECT_NEAR(fourth / n, 3.0, 0.03);
    // P(|X| > 1) = 0.31731, P(|X| > 2) = 0.04550, P(|X| > 3.4426) = 0.000576.
    EXPECT_NEAR(static_cast<double>(beyond_1) / n, 0.31731, 0.003);
    EXPECT_NEAR(static_cast<double>(beyond_2) / n, 0.04550, 0.001);
    EXPECT_NEAR(static_cast<double>(beyond_r) / n, 0.000576, 0.00012);
    // Each bin holds what the normal's distribution function says, within 5 standard
    // errors of a binomial count (and 40 for the nearly empty outer bins).
    auto cdf = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
    for (std::size_t b = 0; b < bins.size(); ++b) {
        const double lo = -4.0 + 0.25 * static_cast<double>(b);
        const double p = cdf(lo + 0.25) - cdf(lo);
        const double expected = p * n;
        const double slack = std::max(5.0 * std::sqrt(expected * (1 - p)), 40.0);
        EXPECT_NEAR(static_cast<double>(bins[b]), expected, slack) << "bin from " << lo;
    }
    // The tail is drawn on both sides.
    EXPECT_GT(positive_tail, beyond_r / 4);
    EXPECT_LT(positive_tail, beyond_r * 3 / 4);
}

}  // namespace
}  // namespace fins::scenario
