// 21 01 ERROR CLEAR, 21 02 ERROR LOG READ, 21 03 ERROR LOG CLEAR through full frames
// (W342 5-3-27 .. 5-3-29).
#include <gtest/gtest.h>

#include <chrono>

#include "fins/commands/error_log.hpp"
#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

using namespace std::chrono;
const system_clock::time_point t0 = sys_days{year{2026} / November / 22} + hours{1};

// The end code without the CPU-error flags: whether a response that clears the last
// error still carries its flag is the dispatcher's business, not ERROR CLEAR's.
std::uint16_t plain(const Reply& r) {
    return static_cast<std::uint16_t>(r.end_code() & 0x7F3F);
}

TEST(ErrorClear, W342_5_3_27_AllIsProgramModeOnly) {
    Harness h;
    h.plc.errors().raise(0x00F7, t0);
    EXPECT_EQ(h.send("2101 FFFF").end_code(), 0x2206 | 0x0040);  // RUN
    h.plc.set_mode(plc::OperatingMode::monitor);
    EXPECT_EQ(h.send("2101 FFFF").end_code(), 0x2205 | 0x0040);
    h.plc.set_mode(plc::OperatingMode::program);
    EXPECT_EQ(plain(h.send("2101 FFFF")), 0x0000);
    EXPECT_TRUE(h.plc.errors().active().empty());
    EXPECT_EQ(h.send("0601").end_code(), 0x0000);
}

TEST(ErrorClear, W342_5_3_27_CurrentClearsTheMostSeriousError) {
    Harness h;
    h.plc.errors().raise(0x00F7, t0);
    h.plc.errors().raise_fal(3, "", t0);
    EXPECT_EQ(h.send("2101 FFFE").end_code(), 0x0000 | 0x0040);
    EXPECT_FALSE(h.plc.errors().is_active(0x4103));
    EXPECT_TRUE(h.plc.errors().is_active(0x00F7));
    EXPECT_EQ(plain(h.send("2101 FFFE")), 0x0000);
    EXPECT_TRUE(h.plc.errors().active().empty());
    EXPECT_EQ(h.send("2101 FFFE").end_code(), 0x0000);  // nothing present: normal
}

TEST(ErrorClear, W342_5_3_27_CurrentFatalErrorNeedsProgramMode) {
    Harness h;
    h.plc.errors().raise_fals(5, "", t0);
    EXPECT_EQ(h.send("2101 FFFE").end_code(), 0x2206 | 0x0080);
    EXPECT_TRUE(h.plc.errors().is_active(0xC105));
    h.plc.set_mode(plc::OperatingMode::program);
    EXPECT_EQ(plain(h.send("2101 FFFE")), 0x0000);
    EXPECT_FALSE(h.plc.errors().has_fatal());
}

TEST(ErrorClear, W342_5_3_27_ProgramModeCodesAreRefusedInRunEvenWhenAbsent) {
    Harness h;
    EXPECT_EQ(h.send("2101 C105").end_code(), 0x2206);
    EXPECT_EQ(h.send("2101 809F").end_code(), 0x2206);
    h.plc.set_mode(plc::OperatingMode::monitor);
    EXPECT_EQ(h.send("2101 80F1").end_code(), 0x2205);
}

TEST(ErrorClear, W342_5_3_27_SpecificCodeAbsentIsNormalUnknownIs110C) {
    Harness h;
    EXPECT_EQ(h.send("2101 4105").end_code(), 0x0000);
    EXPECT_EQ(h.send("2101 1234").end_code(), 0x110C);
    EXPECT_EQ(h.send("2101 0000").end_code(), 0x110C);
    EXPECT_EQ(h.send("2101 00").end_code(), 0x1002);
    EXPECT_EQ(h.send("2101 00F700").end_code(), 0x1001);
}

TEST(ErrorClear, W342_5_3_27_EveryListedCodeIsAcceptedAndClearsItsError) {
    Harness h;
    h.plc.set_mode(plc::OperatingMode::program);
    for (const auto& info : error_code_table()) {
        for (const std::uint16_t code : {info.first, info.last}) {
            ASSERT_TRUE(h.plc.errors().raise(code, t0)) << std::hex << code;
            const auto frame = request_frame("2101" + to_hex(Bytes(std::array<std::uint8_t, 2>{
                                                          static_cast<std::uint8_t>(code >> 8),
                                                          static_cast<std::uint8_t>(code)})));
            EXPECT_EQ(plain(h.send(frame)), 0x0000) << std::hex << code;
            EXPECT_FALSE(h.plc.errors().is_active(code)) << std::hex << code;
        }
    }
    // Non-fatal codes are accepted in RUN mode as well.
    h.plc.set_mode(plc::OperatingMode::run);
    EXPECT_EQ(h.send("2101 00F7").end_code(), 0x0000);
    EXPECT_EQ(h.send("2101 0203").end_code(), 0x0000);
}

TEST(ErrorClear, W342_5_3_27_BatteryErrorRecursWhileTheBatteryIsLow) {
    Harness h;
    h.plc.errors().set_battery_low(true, t0);
    EXPECT_EQ(h.send("2101 00F7").end_code(), 0x0040);  // occurs again at once
    EXPECT_TRUE(h.plc.errors().is_active(0x00F7));
    h.plc.errors().set_battery_low(false, t0);
    EXPECT_EQ(h.send("0101 82000000 0001").end_code(), 0x0000);
}

TEST(ErrorLogRead, W342_5_3_28_RecordsOldestFirstWithTheirTimes) {
    Harness h;
    h.plc.errors().raise(0x00F7, t0 + seconds{5});
    h.plc.errors().raise_fal(0x12, "", sys_days{year{1999} / December / 31} + hours{23});
    auto r = h.send("2102 0000 0014");
    EXPECT_EQ(r.end_code(), 0x1104 | 0x0040);  // 2 stored, 20 asked for
    EXPECT_EQ(r.data_hex(),
              "00 14 00 02 00 02 00 F7 00 00 00 05 22 01 26 11 41 12 00 00 00 00 31 23 99 12");
    r = h.send("2102 0001 0001");
    EXPECT_EQ(r.end_code(), 0x0040);
    EXPECT_EQ(r.data_hex(), "00 14 00 02 00 01 41 12 00 00 00 00 31 23 99 12");
}

TEST(ErrorLogRead, W342_5_3_28_WrapsAtTwentyKeepingTheNewest) {
    Harness h;
    for (std::uint16_t n = 1; n <= 23; ++n) {
        h.plc.errors().raise_fal(n, "", t0 + minutes{n});
        h.plc.errors().clear(static_cast<std::uint16_t>(0x4100 + n), t0);
    }
    auto r = h.send("2102 0000 0014");
    ASSERT_EQ(r.end_code(), 0x0000);
    const auto d = r.data();
    ASSERT_EQ(d.size(), 6u + 20u * 10u);
    EXPECT_EQ(r.data_hex().substr(0, 17), "00 14 00 14 00 14");
    for (std::size_t i = 0; i < 20; ++i) {
        const std::size_t at = 6 + i * 10;
        EXPECT_EQ(d[at], 0x41);
        EXPECT_EQ(d[at + 1], 4 + i) << i;                               // FAL 4 .. FAL 23
        EXPECT_EQ(d[at + 4], ((4 + i) / 10) * 16 + (4 + i) % 10) << i;  // minute, BCD
    }
}

TEST(ErrorLogRead, W342_5_3_28_FewerThanAskedIs1104WithTheStoredRecords) {
    Harness h;
    for (std::uint16_t n = 1; n <= 3; ++n)
        h.plc.errors().raise(static_cast<std::uint16_t>(0x0200 + n), t0);
    auto r = h.send("2102 0002 0005");
    EXPECT_EQ(r.end_code(), 0x1104 | 0x0040);
    EXPECT_EQ(r.data_hex(), "00 14 00 03 00 01 02 03 00 00 00 00 22 01 26 11");
}

TEST(ErrorLogRead, W342_5_3_28_BeyondTheStoredRecordsIs1103WithNoData) {
    Harness h;
    h.plc.errors().raise(0x0201, t0);
    auto r = h.send("2102 0002 0001");
    EXPECT_EQ(r.end_code(), 0x1103 | 0x0040);
    EXPECT_TRUE(r.data().empty());
    // The record number just past the last one is not beyond: zero records.
    r = h.send("2102 0001 0001");
    EXPECT_EQ(r.end_code(), 0x1104 | 0x0040);
    EXPECT_EQ(r.data_hex(), "00 14 00 01 00 00");
}

TEST(ErrorLogRead, W342_5_3_28_EmptyLogAndZeroCount) {
    Harness h;
    auto r = h.send("2102 0000 0014");
    EXPECT_EQ(r.end_code(), 0x1104);
    EXPECT_EQ(r.data_hex(), "00 14 00 00 00 00");
    r = h.send("2102 0000 0000");
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "00 14 00 00 00 00");
    EXPECT_EQ(h.send("2102 0000").end_code(), 0x1002);
}

TEST(ErrorLogClear, W342_5_3_29_ClearsTheCountNotThePresentErrors) {
    Harness h;
    h.plc.errors().raise(0x0201, t0);
    EXPECT_EQ(h.send("2103").end_code(), 0x0040);
    EXPECT_EQ(h.plc.errors().log_size(), 0u);
    EXPECT_TRUE(h.plc.errors().is_active(0x0201));
    EXPECT_EQ(h.send("2102 0000 0001").data_hex(), "00 14 00 00 00 00");
    EXPECT_EQ(h.send("2103 00").end_code(), 0x1001 | 0x0040);
}

// 5-3-29 ("Access right at other device: No") and the 0C 01 / 0C 02 pages' lists
// (5-3-24, 5-3-25: 2103 "No") refuse it while another node holds the access right,
// although the 5-1-2 matrix says OK; the holder itself may clear.
TEST(ErrorLogClear, W342_5_3_29_RefusedWhileAnotherNodeHoldsTheAccessRight) {
    Harness h;
    h.plc.errors().raise(0x0201, t0);
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    EXPECT_EQ(h.send("2103").end_code(), 0x3001 | 0x0040);
    EXPECT_EQ(h.plc.errors().log_size(), 1u);
    h.plc.set_access_right_holder(client_node);
    EXPECT_EQ(h.send("2103").end_code(), 0x0040);
    EXPECT_EQ(h.plc.errors().log_size(), 0u);
}

}  // namespace
}  // namespace fins::test
