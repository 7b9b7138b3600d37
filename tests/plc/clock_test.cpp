// The CPU Unit clock (plc/clock.hpp, W342 5-3-19 / 5-3-20): host local time plus a
// retained offset, the separate day-of-week register, range checks, the year rule,
// and the offset surviving a Plc rebuilt on the same data directory. Time is injected.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "plc/clock.hpp"
#include "plc/plc.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc::test {
namespace {

using std::chrono::seconds;

// 2024-06-15 12:00:00 UTC: a fixed "host now".
const TimePoint host_now{seconds{1'718'452'800}};

ClockWrite setting(std::uint8_t y, std::uint8_t mo, std::uint8_t d, std::uint8_t h, std::uint8_t mi,
                   std::optional<std::uint8_t> s = std::nullopt,
                   std::optional<std::uint8_t> dow = std::nullopt) {
    return ClockWrite{y, mo, d, h, mi, s, dow};
}

TEST(Clock, W342_5_3_19_UnsetClockIsTheHostsLocalTime) {
    Storage storage;
    Clock clock(cj2h(), storage);
    const std::time_t t = std::chrono::system_clock::to_time_t(host_now);
    std::tm tm{};
    ASSERT_NE(::localtime_r(&t, &tm), nullptr);
    const auto r = clock.read(host_now);
    EXPECT_EQ(r.year, tm.tm_year % 100);
    EXPECT_EQ(r.month, tm.tm_mon + 1);
    EXPECT_EQ(r.day, tm.tm_mday);
    EXPECT_EQ(r.hour, tm.tm_hour);
    EXPECT_EQ(r.minute, tm.tm_min);
    EXPECT_EQ(r.second, tm.tm_sec);
    EXPECT_EQ(r.day_of_week, tm.tm_wday);
}

TEST(Clock, WrittenTimeReadsBackAndKeepsRunning) {
    Storage storage;
    Clock clock(cj2h(), storage);
    ASSERT_EQ(clock.write(setting(24, 2, 28, 23, 59, 30, 3), host_now), EndCode::normal_completion);
    EXPECT_EQ(clock.read(host_now), (ClockTime{24, 2, 28, 23, 59, 30, 3}));
    // 2024 is a leap year: 30 s later it is Feb 29, and the day of week moved on.
    EXPECT_EQ(clock.read(host_now + seconds{30}), (ClockTime{24, 2, 29, 0, 0, 0, 4}));
    // Sub-second host time does not matter within the second.
    EXPECT_EQ(clock.read(host_now + std::chrono::milliseconds{999}).second, 30);
}

TEST(Clock, W342_5_3_20_SecondOmittedIsZeroAndDayOfWeekKept) {
    Storage storage;
    Clock clock(cj2h(), storage);
    ASSERT_EQ(clock.write(setting(24, 1, 1, 0, 0, 0, 5), host_now), EndCode::normal_completion);
    // 2024-03-13 is a Wednesday, but the day of week keeps its value (5).
    ASSERT_EQ(clock.write(setting(24, 3, 13, 8, 15), host_now), EndCode::normal_completion);
    EXPECT_EQ(clock.read(host_now), (ClockTime{24, 3, 13, 8, 15, 0, 5}));
}

TEST(Clock, W342_5_3_20_SecondGivenDayOfWeekOmittedKeepsPreviousValue) {
    Storage storage;
    Clock clock(cj2h(), storage);
    ASSERT_EQ(clock.write(setting(24, 1, 1, 0, 0, 0, 2), host_now), EndCode::normal_completion);
    ASSERT_EQ(clock.write(setting(30, 7, 4, 10, 20, 45), host_now), EndCode::normal_completion);
    EXPECT_EQ(clock.read(host_now), (ClockTime{30, 7, 4, 10, 20, 45, 2}));
}

TEST(Clock, W342_5_3_20_DayOfWeekNotCrossCheckedWithTheDate) {
    Storage storage;
    Clock clock(cj2h(), storage);
    // 2024-01-01 was a Monday (1); the PLC accepts Friday (5) without complaint.
    ASSERT_EQ(clock.write(setting(24, 1, 1, 23, 59, 59, 5), host_now), EndCode::normal_completion);
    EXPECT_EQ(clock.read(host_now).day_of_week, 5);
    // At midnight it advances like a real register: Saturday, then Sunday (wraps).
    EXPECT_EQ(clock.read(host_now + seconds{1}).day_of_week, 6);
    EXPECT_EQ(clock.read(host_now + seconds{1 + 86400}).day_of_week, 0);
}

TEST(Clock, W342_5_3_20_OutOfRangeIs110CAndTheClockIsNotSet) {
    Storage storage;
    Clock clock(cj2h(), storage);
    ASSERT_EQ(clock.write(setting(24, 5, 5, 5, 5, 5, 0), host_now), EndCode::normal_completion);
    const auto before = clock.read(host_now);
    const ClockWrite bad[] = {
        setting(24, 0, 1, 0, 0),     setting(24, 13, 1, 0, 0),      setting(24, 1, 0, 0, 0),
        setting(24, 1, 32, 0, 0),    setting(23, 2, 29, 0, 0),      setting(24, 4, 31, 0, 0),
        setting(98, 2, 29, 0, 0),    setting(24, 1, 1, 24, 0),      setting(24, 1, 1, 0, 60),
        setting(24, 1, 1, 0, 0, 60), setting(24, 1, 1, 0, 0, 0, 7), setting(100, 1, 1, 0, 0),
    };
    for (const auto& b : bad) {
        EXPECT_EQ(clock.write(b, host_now), EndCode::parameter_error)
            << int{b.year} << "-" << int{b.month} << "-" << int{b.day} << " " << int{b.hour};
        EXPECT_EQ(clock.read(host_now), before);
    }
    // Leap days that exist: 2024, 2000 ("00"), 2096 ("96").
    for (int y : {24, 0, 96})
        EXPECT_EQ(clock.write(setting(static_cast<std::uint8_t>(y), 2, 29, 0, 0), host_now),
                  EndCode::normal_completion);
}

TEST(Clock, W342_5_3_19_Years98And99Are1998And1999) {
    Storage storage;
    Clock clock(cj2h(), storage);
    ASSERT_EQ(clock.write(setting(99, 12, 31, 23, 59, 59), host_now), EndCode::normal_completion);
    // One second later: 2000-01-01.
    const auto r = clock.read(host_now + seconds{1});
    EXPECT_EQ(r.year, 0);
    EXPECT_EQ(r.month, 1);
    EXPECT_EQ(r.day, 1);
    EXPECT_EQ(r.hour, 0);
    // 1998 is not a leap year, 2000 is: proof that 98 means 1998, 00 means 2000.
    EXPECT_EQ(clock.write(setting(98, 2, 29, 0, 0), host_now), EndCode::parameter_error);
    EXPECT_EQ(clock.write(setting(0, 2, 29, 0, 0), host_now), EndCode::normal_completion);
    // The earliest year the clock can show.
    ASSERT_EQ(clock.write(setting(98, 1, 1, 12, 0, 0), host_now), EndCode::normal_completion);
    EXPECT_EQ(clock.read(host_now).year, 98);
}

TEST(Clock, CalendarHelpers) {
    EXPECT_EQ(Clock::days_in_month(2024, 2), 29U);
    EXPECT_EQ(Clock::days_in_month(2100, 2), 28U);
    EXPECT_EQ(Clock::days_in_month(2000, 2), 29U);
    EXPECT_EQ(Clock::days_in_month(2024, 4), 30U);
    EXPECT_EQ(Clock::days_in_month(2024, 13), 0U);
    EXPECT_EQ(Clock::weekday(Clock::to_civil(1970, 1, 1, 0, 0, 0)), 4U);    // Thursday
    EXPECT_EQ(Clock::weekday(Clock::to_civil(2024, 6, 15, 23, 0, 0)), 6U);  // Saturday
    EXPECT_EQ(Clock::weekday(Clock::to_civil(1969, 12, 31, 0, 0, 0)), 3U);  // Wednesday
}

TEST(Clock, W342_5_3_20_OffsetIsRetainedAcrossAPlcRebuiltOnTheSameDataDirectory) {
    static std::atomic<int> n{0};
    const auto dir = std::filesystem::temp_directory_path() /
                     ("finskit-clock-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
    std::filesystem::remove_all(dir);
    const Profile p = cj2h();
    const auto open = [&] {
        auto s = Storage::open(dir, p.name);
        EXPECT_TRUE(s) << s.error().message();
        return s ? std::move(*s) : std::make_unique<Storage>();
    };
    {
        Plc plc(p, open());
        ASSERT_TRUE(plc.storage().seal());
        ASSERT_EQ(plc.clock().write(setting(31, 10, 9, 8, 7, 6, 1), host_now),
                  EndCode::normal_completion);
    }
    {
        Plc plc(p, open());
        ASSERT_TRUE(plc.storage().seal());
        EXPECT_TRUE(plc.storage().restored());
        EXPECT_EQ(plc.clock().read(host_now), (ClockTime{31, 10, 9, 8, 7, 6, 1}));
        EXPECT_EQ(plc.clock().read(host_now + seconds{3600}).hour, 9);
    }
    // Without a data directory nothing is retained: host time again.
    Plc fresh(p);
    Storage heap;
    EXPECT_EQ(fresh.clock().read(host_now), Clock(p, heap).read(host_now));
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace fins::plc::test
