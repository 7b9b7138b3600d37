// plc::ErrorState: error words and flags (W342 5-3-17, 5-1-3), priorities, FAL/FALS
// messages (5-3-23), clearing (5-3-27) and the 20-record error log (5-3-28, 5-3-29).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "plc/errors.hpp"
#include "plc/injections.hpp"
#include "plc/plc.hpp"

namespace fins::plc {
namespace {

using namespace std::chrono;

const system_clock::time_point t0 = sys_days{year{2026} / November / 22} + hours{1};

TEST(ErrorState, W342_5_1_3_FlagsFollowTheErrorClass) {
    Plc plc;
    auto& e = plc.errors();
    EXPECT_EQ(e.end_code_flags(), 0x0000);
    ASSERT_TRUE(e.raise(0x00F7, t0));
    EXPECT_EQ(e.end_code_flags(), 0x0040);
    EXPECT_EQ(e.non_fatal_word(), 0x0010);  // bit 4 battery
    ASSERT_TRUE(e.raise_fals(5, "STOP", t0));
    EXPECT_EQ(e.end_code_flags(), 0x00C0);
    EXPECT_EQ(e.fatal_word(), 0x0040);  // bit 6 FALS
    EXPECT_TRUE(e.has_fatal());
    e.clear_all(t0);
    EXPECT_EQ(e.end_code_flags(), 0x0000);
    EXPECT_EQ(e.fatal_word(), 0x0000);
    EXPECT_EQ(e.non_fatal_word(), 0x0000);
}

TEST(ErrorState, W342_5_3_17_EveryCodeSetsItsBit) {
    for (const auto& info : error_code_table()) {
        Plc plc;
        auto& e = plc.errors();
        ASSERT_TRUE(e.raise(info.first, t0)) << info.name;
        const std::uint16_t word = info.fatal ? e.fatal_word() : e.non_fatal_word();
        const std::uint16_t other = info.fatal ? e.non_fatal_word() : e.fatal_word();
        EXPECT_EQ(word, info.bit >= 0 ? 1U << info.bit : 0U) << info.name;
        EXPECT_EQ(other, 0) << info.name;
        EXPECT_EQ(e.end_code_flags(), info.fatal ? 0x0080 : 0x0040) << info.name;
        EXPECT_EQ(e.most_serious()->code, info.first) << info.name;
    }
}

TEST(ErrorState, W342_5_3_27_UnknownCodesAndFalNumbersAreRefused) {
    Plc plc;
    auto& e = plc.errors();
    EXPECT_FALSE(e.raise(0x1234, t0));
    EXPECT_FALSE(e.raise_fal(0, "", t0));
    EXPECT_FALSE(e.raise_fal(512, "", t0));
    EXPECT_FALSE(e.raise_fals(600, "", t0));
    EXPECT_FALSE(e.raise_fal(1, "SEVENTEEN CHARS!!", t0));
    EXPECT_TRUE(e.raise_fal(511, "", t0));
    EXPECT_TRUE(e.is_active(0x42FF));
    EXPECT_EQ(e.log_size(), 1u);
}

TEST(ErrorState, W342_5_3_17_MostSeriousIsFatalThenBitOrderThenNewest) {
    Plc plc;
    auto& e = plc.errors();
    e.raise(0x00F7, t0);  // battery, non-fatal bit 4
    e.raise(0x0203, t0);  // CPU Bus Unit 3 error, non-fatal bit 7
    EXPECT_EQ(e.most_serious()->code, 0x0203);
    e.raise_fal(2, "FIRST", t0);
    e.raise_fal(7, "SECOND", t0);
    EXPECT_EQ(e.most_serious()->code, 0x4107);  // FAL outranks; the newest FAL wins
    EXPECT_EQ(e.status_message(), "SECOND");
    e.raise(0x809F, t0);  // cycle time too long: fatal
    EXPECT_EQ(e.most_serious()->code, 0x809F);
    EXPECT_EQ(e.status_message(), "SECOND");  // the message comes from FAL/FALS only
    e.raise_fals(9, "HALT", t0);
    EXPECT_EQ(e.most_serious()->code, 0x809F);  // cycle time (bit 8) outranks FALS (bit 6)
    EXPECT_EQ(e.status_message(), "HALT");
}

TEST(ErrorState, W342_5_3_23_FalMessagesByNumberFalsFirst) {
    Plc plc;
    auto& e = plc.errors();
    EXPECT_FALSE(e.fal_message(3).has_value());
    e.raise_fal(3, "FAL THREE", t0);
    EXPECT_EQ(e.fal_message(3), "FAL THREE");
    e.raise_fals(3, "FALS THREE", t0);
    EXPECT_EQ(e.fal_message(3), "FALS THREE");
    e.clear(0xC103, t0);
    EXPECT_EQ(e.fal_message(3), "FAL THREE");
    e.raise_fal(3, "UPDATED", t0);  // already present: message refreshed, not logged
    EXPECT_EQ(e.fal_message(3), "UPDATED");
    EXPECT_EQ(e.log_size(), 2u);
    EXPECT_FALSE(e.fal_message(0).has_value());
    EXPECT_FALSE(e.fal_message(512).has_value());
}

TEST(ErrorState, W342_5_3_27_BatteryErrorRecursWhileTheCauseRemains) {
    Plc plc;
    auto& e = plc.errors();
    e.set_battery_low(true, t0);
    EXPECT_TRUE(e.is_active(0x00F7));
    EXPECT_EQ(e.log_size(), 1u);
    EXPECT_TRUE(e.clear(0x00F7, t0 + seconds{1}));
    EXPECT_TRUE(e.is_active(0x00F7));  // "the same error will immediately occur again"
    EXPECT_EQ(e.log_size(), 2u);
    e.clear_all(t0);
    EXPECT_TRUE(e.is_active(0x00F7));
    e.set_battery_low(false, t0);  // battery replaced
    EXPECT_FALSE(e.is_active(0x00F7));
    EXPECT_EQ(e.end_code_flags(), 0x0000);
    EXPECT_FALSE(e.clear(0x00F7, t0));  // not present: nothing to do
}

TEST(ErrorState, W342_5_3_28_LogKeepsTheTwentyNewestOldestFirst) {
    Plc plc;
    auto& e = plc.errors();
    for (std::uint16_t n = 1; n <= 25; ++n) {
        ASSERT_TRUE(e.raise_fal(n, "", t0 + minutes{n}));
        e.clear(static_cast<std::uint16_t>(0x4100 + n), t0);
    }
    ASSERT_EQ(e.log_size(), 20u);
    EXPECT_EQ(e.log_record(0).error_code, 0x4106);  // FAL 1-5 dropped
    EXPECT_EQ(e.log_record(19).error_code, 0x4119);
    EXPECT_EQ(e.log_record(0).time, (LogTime{26, 11, 22, 1, 6, 0}));
    EXPECT_EQ(e.log_record(19).detail, 0x0000);
}

TEST(ErrorState, W342_5_3_29_ClearResetsTheCountOnly) {
    Plc plc;
    auto& e = plc.errors();
    e.raise(0x00F7, t0);
    e.clear_log();
    EXPECT_EQ(e.log_size(), 0u);
    EXPECT_TRUE(e.is_active(0x00F7));  // the error itself stays
    e.raise(0x0203, t0);
    EXPECT_EQ(e.log_size(), 1u);
    EXPECT_EQ(e.log_record(0).error_code, 0x0203);
}

TEST(ErrorState, ActiveListIsBounded) {
    Plc plc;
    auto& e = plc.errors();
    for (std::uint16_t n = 1; n <= max_active_errors; ++n)
        ASSERT_TRUE(e.raise_fal(n, "", t0));
    EXPECT_FALSE(e.raise_fal(100, "", t0));
    EXPECT_TRUE(e.raise_fal(1, "AGAIN", t0));  // refreshing one present is still fine
    EXPECT_EQ(e.active().size(), max_active_errors);
}

TEST(ErrorState, LogIsRetainedAcrossARestartPresentErrorsAreNot) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("fins-errors-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    {
        auto storage = Storage::open(dir, "errors-test");
        ASSERT_TRUE(storage) << storage.error().message();
        Plc plc(cj2h(), std::move(*storage));
        ASSERT_TRUE(plc.storage().seal());
        plc.errors().raise(0x00F7, t0);
        plc.write_access_log().record({0, 20, 0}, {0x01, 0x02}, EndCode::normal_completion, t0);
    }
    {
        auto storage = Storage::open(dir, "errors-test");
        ASSERT_TRUE(storage) << storage.error().message();
        Plc plc(cj2h(), std::move(*storage));
        ASSERT_TRUE(plc.storage().seal());
        EXPECT_EQ(plc.errors().log_size(), 1u);
        EXPECT_EQ(plc.errors().log_record(0).error_code, 0x00F7);
        EXPECT_FALSE(plc.errors().is_active(0x00F7));
        EXPECT_EQ(plc.write_access_log().size(), 1u);
    }
    std::filesystem::remove_all(dir);
}

TEST(Injections, ValidateNamesTheFirstBadField) {
    Injections in;
    EXPECT_EQ(validate(in), "");
    in.fal = {{5, "OK"}, {600, "BAD"}};
    EXPECT_EQ(validate(in), "fal[1].number: 600 is not 1-511");
    in.fal = {{5, "SEVENTEEN CHARS!!"}};
    EXPECT_EQ(validate(in), "fal[0].message: longer than 16 characters");
    in.fal.clear();
    in.messages[2] = std::string(33, 'x');
    EXPECT_EQ(validate(in), "messages[2]: longer than 32 characters");
    in.messages[2].reset();
    in.errors = {0x4105};
    EXPECT_EQ(validate(in), "errors[0]: FAL/FALS codes go in fal / fals");
    in.errors = {0x1234};
    EXPECT_EQ(validate(in), "errors[0]: not an error code of W342 5-3-27");
}

TEST(Injections, ApplyRaisesEverythingAndSkipsInvalidEntries) {
    Plc plc;
    Injections in;
    in.battery_error = true;
    in.fal = {{5, "LOW OIL"}, {0, "SKIPPED"}};
    in.fals = FalInjection{9, "HALT"};
    in.messages[3] = "HELLO";
    in.errors = {0x0203, 0x1234};
    apply(in, plc, t0);
    auto& e = plc.errors();
    EXPECT_TRUE(e.battery_low());
    EXPECT_TRUE(e.is_active(0x00F7));
    EXPECT_TRUE(e.is_active(0x4105));
    EXPECT_TRUE(e.is_active(0xC109));
    EXPECT_TRUE(e.is_active(0x0203));
    EXPECT_EQ(e.active().size(), 4u);
    EXPECT_EQ(e.end_code_flags(), 0x00C0);
    EXPECT_EQ(plc.messages().text(3), "HELLO");
    EXPECT_EQ(plc.messages().present(), 0x08);
}

}  // namespace
}  // namespace fins::plc
