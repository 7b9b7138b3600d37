// CLOCK READ 07 01 and CLOCK WRITE 07 02 through the dispatcher with full frames
// (W342 5-3-19, 5-3-20 and their 5-1-2 rows). Time is injected.
#include <chrono>

#include <gtest/gtest.h>

#include "fins/commands/clock.hpp"
#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

using std::chrono::seconds;

class ClockHandler : public ::testing::Test {
  protected:
    ClockHandler() { h.context.now = plc::TimePoint{seconds{1'718'452'800}}; }  // 2024-06-15
    Harness h;
};

TEST_F(ClockHandler, W342_5_3_19_ReadsSevenBcdBytes) {
    const auto r = h.send("0701");
    ASSERT_EQ(r.end_code(), 0x0000);
    ASSERT_EQ(r.data().size(), 7U);
    const auto decoded = ClockRead{}.decode_response(r.data());
    ASSERT_TRUE(decoded);  // valid BCD
    EXPECT_EQ(decoded->time, h.plc.clock().read(h.context.now));
    EXPECT_LE(decoded->time.day_of_week, 6);
}

TEST_F(ClockHandler, W342_5_3_19_ParametersAre1001) {
    EXPECT_EQ(h.send("0701 00").end_code(), 0x1001);
}

TEST_F(ClockHandler, W342_5_3_20_WriteThenRead) {
    const auto w = h.send("0702 25 12 31 23 59 58 03");
    EXPECT_EQ(w.end_code(), 0x0000);
    EXPECT_TRUE(w.data().empty());
    EXPECT_EQ(h.send("0701").data_hex(), "25 12 31 23 59 58 03");
    h.context.now += seconds{2};
    EXPECT_EQ(h.send("0701").data_hex(), "26 01 01 00 00 00 04");
}

TEST_F(ClockHandler, W342_5_3_20_SecondAndDayOfWeekOmitted) {
    ASSERT_EQ(h.send("0702 24 01 01 00 00 00 06").end_code(), 0x0000);
    // Five bytes: second 00, the day of week keeps its value (06).
    ASSERT_EQ(h.send("0702 24 03 13 08 15").end_code(), 0x0000);
    EXPECT_EQ(h.send("0701").data_hex(), "24 03 13 08 15 00 06");
    // Six bytes: the second is set, the day of week still kept.
    ASSERT_EQ(h.send("0702 24 03 13 08 15 42").end_code(), 0x0000);
    EXPECT_EQ(h.send("0701").data_hex(), "24 03 13 08 15 42 06");
}

TEST_F(ClockHandler, W342_5_3_20_DayOfWeekIsNotCrossChecked) {
    // 2024-03-13 is a Wednesday (03); Sunday (00) is accepted as given.
    ASSERT_EQ(h.send("0702 24 03 13 08 15 00 00").end_code(), 0x0000);
    EXPECT_EQ(h.send("0701").data_hex(), "24 03 13 08 15 00 00");
}

TEST_F(ClockHandler, W342_5_3_20_BadDataIs110CAndTheClockIsNotSet) {
    ASSERT_EQ(h.send("0702 24 05 05 05 05 05 00").end_code(), 0x0000);
    const auto before = h.send("0701").data_hex();
    for (const char* bad : {"0702 2A 01 01 00 00",           // not BCD
                            "0702 24 01 01 00 00 6A",        // second not BCD
                            "0702 24 13 01 00 00",           // month 13
                            "0702 24 00 01 00 00",           // month 0
                            "0702 23 02 29 00 00",           // not a leap year
                            "0702 24 04 31 00 00",           // April has 30 days
                            "0702 24 01 01 24 00",           // hour 24
                            "0702 24 01 01 00 60",           // minute 60
                            "0702 24 01 01 00 00 60",        // second 60
                            "0702 24 01 01 00 00 00 07"}) {  // day of week 7
        EXPECT_EQ(h.send(bad).end_code(), 0x110C) << bad;
        EXPECT_EQ(h.send("0701").data_hex(), before) << bad;
    }
}

TEST_F(ClockHandler, W342_5_1_3_LengthErrors) {
    EXPECT_EQ(h.send("0702 24 01 01 00").end_code(), 0x1002);
    EXPECT_EQ(h.send("0702").end_code(), 0x1002);
    EXPECT_EQ(h.send("0702 24 01 01 00 00 00 00 00").end_code(), 0x1001);
}

TEST_F(ClockHandler, W342_5_1_2_WriteNeedsTheAccessRightAndNoNetworkProtection) {
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    EXPECT_EQ(h.send("0702 24 01 01 00 00").end_code(), 0x3001);
    EXPECT_EQ(h.send("0701").end_code(), 0x0000);  // reading is always allowed
    h.plc.set_access_right_holder(std::nullopt);
    h.plc.set_network_write_protection(true);
    EXPECT_EQ(h.send("0702 24 01 01 00 00").end_code(), 0x2102);
    EXPECT_EQ(h.send("0701").end_code(), 0x0000);
}

TEST_F(ClockHandler, W342_5_1_2_AcceptedInEveryModeAndUnderUmProtection) {
    h.plc.set_um_read_protection(true);
    h.plc.set_dip_write_protection(true);
    for (auto mode :
         {plc::OperatingMode::program, plc::OperatingMode::monitor, plc::OperatingMode::run}) {
        h.plc.set_mode(mode);
        EXPECT_EQ(h.send("0701").end_code(), 0x0000);
        EXPECT_EQ(h.send("0702 24 01 01 00 00").end_code(), 0x0000);
    }
}

}  // namespace
}  // namespace fins::test
