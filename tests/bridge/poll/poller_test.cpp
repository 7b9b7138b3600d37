// The poller's pure parts, driven by an invented clock (no sockets, no sleeping): the
// drift-free tick grid and its overrun count, the start phases, the back-off with full
// jitter (poll_schedule.hpp). Answer matching, SIDs and retries are fins::Client's
// (tests/client); the poller on it: poller_engine_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <vector>

#include "bridge/poll/poll_schedule.hpp"
#include "fins/commands/memory_area.hpp"

namespace fins::bridge {
namespace {

using namespace std::chrono_literals;
using Clock = PollClock;

// An invented time far from the clock's epoch.
const Clock::time_point t0 = Clock::time_point{} + 1000h;

TEST(PollerTickGrid, StaysOnItsGridHoweverLateEachTickRuns) {
    TickGrid grid(t0, 100ms, 0.25);
    EXPECT_EQ(grid.next(), t0 + 25ms);
    // Each tick runs up to 99 ms late (a busy loop): the grid does not move.
    for (int k = 0; k < 1000; ++k) {
        const auto late = std::chrono::milliseconds((k * 37) % 100);
        EXPECT_EQ(grid.advance(grid.next() + late), 0u) << k;
        EXPECT_EQ(grid.next(), t0 + 25ms + (k + 1) * 100ms) << k;
    }
}

TEST(PollerTickGrid, SkipsAndCountsTheGridPointsItWasTooLateFor) {
    TickGrid grid(t0, 100ms, 0.0);
    // The tick due at t0 runs at t0 + 250 ms: t0 + 100 and t0 + 200 are missed.
    EXPECT_EQ(grid.advance(t0 + 250ms), 2u);
    EXPECT_EQ(grid.next(), t0 + 300ms);
    // Exactly on the next grid point is not late: the one after it is next.
    EXPECT_EQ(grid.advance(t0 + 300ms), 0u);
    EXPECT_EQ(grid.next(), t0 + 400ms);
    // Running exactly when the following point is due misses that point.
    EXPECT_EQ(grid.advance(t0 + 500ms), 1u);
    EXPECT_EQ(grid.next(), t0 + 600ms);
}

// Aligned to 1 ms: the first tick is the next whole millisecond of the clock at or after
// start + phase x interval, every tick stays on whole milliseconds, and two grids started
// a few microseconds apart with the same phase tick at the same time point (one wake-up).
TEST(PollerTickGrid, AlignedGridsStartedApartShareTheirTicks) {
    const auto start = t0 + 123456ns;
    TickGrid a(start, 100ms, 0.25, 1ms);
    EXPECT_EQ(a.next(), t0 + 26ms) << "25.123456 ms rounded up";
    EXPECT_EQ(a.next().time_since_epoch() % 1ms, Clock::duration::zero());
    TickGrid b(start + 37us, 100ms, 0.25, 1ms);
    EXPECT_EQ(b.next(), a.next());
    TickGrid exact(t0, 100ms, 0.25, 1ms);
    EXPECT_EQ(exact.next(), t0 + 25ms) << "already whole: not moved";
    for (int k = 0; k < 10; ++k) {
        EXPECT_EQ(a.advance(a.next() + 3ms), 0u);
        EXPECT_EQ(a.next(), t0 + 26ms + (k + 1) * 100ms);
    }
}

// 5 ms, or a twentieth of a shorter interval: every interval keeps 20 time points.
TEST(PollerTickGrid, AlignmentIsFiveMillisecondsOrATwentiethOfTheInterval) {
    EXPECT_EQ(tick_alignment(100ms), 5ms);
    EXPECT_EQ(tick_alignment(60s), 5ms);
    EXPECT_EQ(tick_alignment(100ms) * 20, 100ms);
    EXPECT_EQ(tick_alignment(10ms), 500us);
    EXPECT_EQ(tick_alignment(1ms), 50us);
}

TEST(PollerPhases, SpreadEvenlyOverTheIntervalForAnyCount) {
    for (std::size_t n : {2u, 3u, 10u, 100u, 1000u}) {
        std::vector<double> phases;
        for (std::size_t i = 0; i < n; ++i) {
            const double p = spread_phase(i);
            ASSERT_GE(p, 0.0);
            ASSERT_LT(p, 1.0);
            phases.push_back(p);
        }
        std::sort(phases.begin(), phases.end());
        double widest = 1.0 - phases.back() + phases.front();  // around the end
        for (std::size_t i = 1; i < n; ++i)
            widest = std::max(widest, phases[i] - phases[i - 1]);
        // Three-distance theorem: golden-ratio gaps are within a factor ~2.6 of 1/n.
        EXPECT_LT(widest, 2.7 / static_cast<double>(n)) << n;
    }
}

TEST(PollerBackoff, CapDoublesFromTheMinimumUpToTheMaximum) {
    Backoff b(500ms, 30000ms, 1);
    EXPECT_EQ(b.cap(0), 500ms);
    EXPECT_EQ(b.cap(1), 1000ms);
    EXPECT_EQ(b.cap(5), 16000ms);
    EXPECT_EQ(b.cap(6), 30000ms);
    EXPECT_EQ(b.cap(1000), 30000ms);
}

TEST(PollerBackoff, FullJitterSpreadsEachWaitOverZeroToTheCap) {
    // A thousand PLCs failing at once: their first retries spread over [0, 500 ms).
    std::vector<std::int64_t> first;
    for (std::uint64_t seed = 0; seed < 1000; ++seed) {
        Backoff b(500ms, 30000ms, seed);
        first.push_back(b.next().count());
        for (unsigned n = 1; n < 10; ++n) {
            const auto wait = b.next();
            EXPECT_GE(wait.count(), 0);
            EXPECT_LE(wait, b.cap(n));
        }
        EXPECT_EQ(b.attempt(), 10u);
        b.reset();
        EXPECT_EQ(b.attempt(), 0u);
        EXPECT_LE(b.next(), 500ms);
    }
    std::sort(first.begin(), first.end());
    EXPECT_GE(first.front(), 0);
    EXPECT_LT(first.back(), 500);
    // Uniform: each 100 ms tenth holds 20 % +- a margin, none is a crowd.
    for (std::int64_t from = 0; from < 500; from += 100) {
        const auto in = std::count_if(first.begin(), first.end(),
                                      [&](auto w) { return w >= from && w < from + 100; });
        EXPECT_GT(in, 130) << from;
        EXPECT_LT(in, 270) << from;
    }
}

}  // namespace
}  // namespace fins::bridge
