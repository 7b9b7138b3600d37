// The simulated scan cycle (plc/scan_cycle.hpp): the deterministic timeline, the 06 20
// statistics (W342 5-3-18) checked against a brute-force walk over the cycles, start /
// stop / initialize, and area 07 refreshed at cycle boundaries (5-2-2). Time is
// injected: every time point is built from ticks, nothing sleeps.
#include <malloc.h>

#include <algorithm>
#include <chrono>

#include <gtest/gtest.h>

#include "plc/io_memory_test_util.hpp"
#include "plc/plc.hpp"
#include "plc/scan_cycle.hpp"

namespace fins::plc::test {
namespace {

using Ticks = ScanCycle::Ticks;

TimePoint at_tick(Ticks t) {
    return TimePoint{std::chrono::microseconds{t * ScanCycle::microseconds_per_tick}};
}

Profile with_program(std::uint16_t kwords) {
    Profile p = cj2h();
    p.program_kwords = kwords;
    return p;
}

// Cycle times from first principles: every cycle's length, summed and compared.
CycleTimes brute_force(Ticks base, std::uint64_t first, std::uint64_t stats_first,
                       std::uint64_t end) {
    CycleTimes t;
    if (end <= first) return t;
    const auto m = std::min<std::uint64_t>(end - first, 8);
    Ticks sum = 0;
    for (auto k = end - m; k < end; ++k)
        sum += ScanCycle::cycle_length(base, k);
    t.average = static_cast<std::uint32_t>(sum / static_cast<Ticks>(m));
    const auto from = std::max(first, stats_first);
    if (end <= from) return t;
    Ticks hi = 0;
    Ticks lo = 1'000'000;
    for (auto k = from; k < end; ++k) {
        hi = std::max(hi, ScanCycle::cycle_length(base, k));
        lo = std::min(lo, ScanCycle::cycle_length(base, k));
    }
    t.maximum = static_cast<std::uint32_t>(hi);
    t.minimum = static_cast<std::uint32_t>(lo);
    return t;
}

TEST(ScanCycle, BaseCycleDependsOnTheProfile) {
    EXPECT_EQ(ScanCycle::base_cycle(with_program(100)), 15);  // 1.5 ms
    EXPECT_EQ(ScanCycle::base_cycle(with_program(0)), 5);     // 0.5 ms minimum
    EXPECT_LT(ScanCycle::base_cycle(with_program(20)), ScanCycle::base_cycle(with_program(250)));
}

TEST(ScanCycle, TimelineStartsAndIndexesAgree) {
    for (Ticks base : {5, 15, 1000}) {
        Ticks sixteen = 0;
        for (std::uint64_t k = 0; k < 200; ++k) {
            const auto start = ScanCycle::cycle_start(base, k);
            const auto next = ScanCycle::cycle_start(base, k + 1);
            EXPECT_EQ(next - start, ScanCycle::cycle_length(base, k));
            EXPECT_GE(ScanCycle::cycle_length(base, k), base - 2);
            EXPECT_LE(ScanCycle::cycle_length(base, k), base + 3);
            EXPECT_EQ(ScanCycle::cycle_at(base, start), k);
            EXPECT_EQ(ScanCycle::cycle_at(base, next - 1), k);
            if (k < 16) sixteen += ScanCycle::cycle_length(base, k);
        }
        EXPECT_EQ(sixteen, 16 * base);
    }
    // Before the epoch: cycle 0.
    EXPECT_EQ(ScanCycle::cycle_at(15, -100), 0U);
}

TEST(ScanCycle, W342_5_3_18_StatisticsMatchEveryCycleWalkedByHand) {
    const Profile p = with_program(100);
    const Ticks base = ScanCycle::base_cycle(p);
    Storage storage;
    ScanCycle cycle(p, storage);
    const Ticks t0 = 17'000'000'000;                           // ~2023-11, 0.1 ms ticks
    EXPECT_EQ(cycle.times(at_tick(t0 + 1000)), CycleTimes{});  // not powered: nothing ran
    cycle.power_on(at_tick(t0));                               // power-on in RUN: operation starts
    const auto first = ScanCycle::cycle_at(base, t0) + 1;
    EXPECT_EQ(cycle.times(at_tick(t0)), CycleTimes{});
    for (Ticks dt : {0, 10, 20, 31, 45, 100, 119, 240, 241, 1000, 12345}) {
        const auto end = ScanCycle::cycle_at(base, t0 + dt);
        EXPECT_EQ(cycle.times(at_tick(t0 + dt)), brute_force(base, first, first, end)) << dt;
        EXPECT_EQ(cycle.cycles(at_tick(t0 + dt)), end > first ? end - first : 0) << dt;
    }
}

TEST(ScanCycle, W342_5_3_18_AverageIsTheLastEightCycles) {
    const Profile p = with_program(100);
    const Ticks base = ScanCycle::base_cycle(p);
    Storage storage;
    ScanCycle cycle(p, storage);
    cycle.start(at_tick(0));
    const auto now = at_tick(base * 100);
    const auto end = ScanCycle::cycle_at(base, base * 100);
    Ticks sum = 0;
    for (auto k = end - 8; k < end; ++k)
        sum += ScanCycle::cycle_length(base, k);
    EXPECT_EQ(cycle.times(now).average, static_cast<std::uint32_t>(sum / 8));
    // Over 16+ cycles every jitter value has been seen.
    EXPECT_EQ(cycle.times(now).maximum, static_cast<std::uint32_t>(base + 3));
    EXPECT_EQ(cycle.times(now).minimum, static_cast<std::uint32_t>(base - 2));
}

TEST(ScanCycle, DeterministicForTheSameTimePoints) {
    const Profile p = with_program(250);
    Storage s1;
    Storage s2;
    ScanCycle a(p, s1);
    ScanCycle b(p, s2);
    a.power_on(at_tick(1000));
    b.power_on(at_tick(1000));
    for (Ticks t : {1000, 1003, 1500, 9999, 123456})
        EXPECT_EQ(a.times(at_tick(t)), b.times(at_tick(t))) << t;
}

TEST(ScanCycle, W342_5_3_18_InitializeRestartsMaximumAndMinimum) {
    const Profile p = with_program(100);
    const Ticks base = ScanCycle::base_cycle(p);
    Storage storage;
    ScanCycle cycle(p, storage);
    cycle.start(at_tick(0));
    const Ticks init = 5 * 16 * base + 40;
    cycle.initialize(at_tick(init));
    const auto stats_first = ScanCycle::cycle_at(base, init);
    EXPECT_EQ(cycle.times(at_tick(init)).maximum, 0U);  // nothing measured since the request yet
    EXPECT_NE(cycle.times(at_tick(init)).average, 0U);  // the last 8 cycles regardless
    for (Ticks dt : {5, 20, 33, 60, 200}) {
        const auto end = ScanCycle::cycle_at(base, init + dt);
        EXPECT_EQ(cycle.times(at_tick(init + dt)), brute_force(base, 1, stats_first, end)) << dt;
    }
}

TEST(ScanCycle, W342_5_3_18_MaxMinInitializedWhenOperationStarts) {
    const Profile p = with_program(100);
    const Ticks base = ScanCycle::base_cycle(p);
    Storage storage;
    ScanCycle cycle(p, storage);
    cycle.start(at_tick(0));
    const auto before = cycle.times(at_tick(1000));
    EXPECT_NE(before.maximum, 0U);

    cycle.stop(at_tick(1000));  // PROGRAM: frozen
    EXPECT_FALSE(cycle.running());
    EXPECT_EQ(cycle.times(at_tick(5000)), before);

    cycle.start(at_tick(5000));  // RUN again: starts over at the next cycle
    EXPECT_TRUE(cycle.running());
    EXPECT_EQ(cycle.times(at_tick(5000)), CycleTimes{});
    EXPECT_EQ(cycle.cycles(at_tick(5000)), 0U);
    const auto first = ScanCycle::cycle_at(base, 5000) + 1;
    EXPECT_EQ(cycle.times(at_tick(5100)),
              brute_force(base, first, first, ScanCycle::cycle_at(base, 5100)));
    // start() while running changes nothing (RUN <-> MONITOR).
    const auto running = cycle.times(at_tick(5100));
    cycle.start(at_tick(5100));
    EXPECT_EQ(cycle.times(at_tick(5100)), running);
}

TEST(ScanCycle, W342_5_3_18_PoweredUpInProgramModeNothingRan) {
    Storage storage;
    ScanCycle cycle(with_program(100), storage);
    cycle.stop(at_tick(1'000'000));  // Plc::power_on in PROGRAM mode
    EXPECT_TRUE(cycle.powered());
    EXPECT_EQ(cycle.times(at_tick(2'000'000)), CycleTimes{});
    EXPECT_EQ(cycle.cycles(at_tick(2'000'000)), 0U);
    cycle.power_on(at_tick(2'000'000));  // already on: changes nothing
    EXPECT_FALSE(cycle.running());
}

TEST(ScanCycle, HostClockSetBackCountsNoCyclesAndDoesNotCrash) {
    Storage storage;
    ScanCycle cycle(with_program(100), storage);
    cycle.power_on(at_tick(1'000'000));
    EXPECT_NE(cycle.cycles(at_tick(2'000'000)), 0U);
    EXPECT_EQ(cycle.cycles(at_tick(10)), 0U);
    EXPECT_EQ(cycle.times(at_tick(10)), CycleTimes{});
    EXPECT_EQ(cycle.times(TimePoint{std::chrono::seconds{-5}}), CycleTimes{});
}

// Linux only: mallinfo2 is glibc's (docs/windows.md).
#ifndef _WIN32
TEST(ScanCycle, ReadingDoesNotAllocate) {
    Storage storage;
    ScanCycle cycle(cj2h(), storage);
    cycle.power_on(at_tick(1));
    const auto before = ::mallinfo2();
    std::uint64_t sum = 0;
    for (Ticks t = 0; t < 1000; ++t)
        sum += cycle.times(at_tick(1'000'000 + t * 37)).average + cycle.cycles(at_tick(t));
    EXPECT_NE(sum, 0U);
    const auto after = ::mallinfo2();
    EXPECT_EQ(after.uordblks, before.uordblks);
    EXPECT_EQ(after.hblkhd, before.hblkhd);
}
#endif

TEST(ScanCycle, W342_5_2_2_ClockPulsesRefreshAtCycleBoundaries) {
    const Profile p = with_program(100);
    const Ticks base = ScanCycle::base_cycle(p);
    // The 0.02 s pulse turns OFF at 10.0 ms (tick 100). Find the cycle in progress then.
    const auto k = ScanCycle::cycle_at(base, 100);
    const auto start = ScanCycle::cycle_start(base, k);
    ASSERT_LT(start, 100);  // 100 is not a boundary for base 15
    // Until the next boundary the pulse still shows what it was at the start: ON.
    EXPECT_TRUE(ScanCycle::clock_pulse(p, ClockPulse::point_zero_two_second, at_tick(100)));
    EXPECT_FALSE(ScanCycle::clock_pulse(p, ClockPulse::point_zero_two_second,
                                        at_tick(ScanCycle::cycle_start(base, k + 1))));
    // Everywhere: the value at the start of the cycle in progress.
    const std::int64_t periods_us[] = {60'000'000, 1'000'000, 200'000, 100'000, 20'000};
    for (Ticks t = 0; t < 2'000'000; t += 977) {
        const auto refreshed = ScanCycle::cycle_start(base, ScanCycle::cycle_at(base, t)) * 100;
        for (std::size_t i = 0; i < 5; ++i) {
            const bool expected = refreshed % periods_us[i] < periods_us[i] / 2;
            EXPECT_EQ(ScanCycle::clock_pulse(p, static_cast<ClockPulse>(i), at_tick(t)), expected)
                << t << " pulse " << i;
        }
    }
}

TEST(ScanCycle, W342_5_2_2_ConditionFlagsAlwaysOnAndOff) {
    EXPECT_TRUE(ScanCycle::condition_flag(ConditionFlag::always_on));
    EXPECT_FALSE(ScanCycle::condition_flag(ConditionFlag::always_off));
    EXPECT_FALSE(ScanCycle::condition_flag(ConditionFlag::equals));
    EXPECT_FALSE(ScanCycle::condition_flag(ConditionFlag::carry));
}

TEST(ScanCycle, W342_5_2_2_Area07ReadThroughIoMemoryComesFromTheScanCycle) {
    // Area 07 words 0000-0004 through IoMemory equal the scan cycle's pulses, in every
    // mode: the CPU Unit keeps cycling in PROGRAM mode.
    Plc plc(with_program(100));
    plc.scan_cycle().stop(at_tick(0));
    for (Ticks t : {100, 2000, 5001, 12345, 600001}) {
        const auto bytes = read(plc.memory(), at(0x07, 0x0000), 5, at_tick(t));
        ASSERT_EQ(bytes.size(), 5U);
        for (std::size_t i = 0; i < 5; ++i)
            EXPECT_EQ(bytes[i],
                      ScanCycle::clock_pulse(plc.profile(), static_cast<ClockPulse>(i), at_tick(t))
                          ? 1
                          : 0)
                << t << " pulse " << i;
    }
    EXPECT_EQ(read(plc.memory(), at(0x07, 0x100E), 2), (Bytes8{0, 1}));
}

}  // namespace
}  // namespace fins::plc::test
