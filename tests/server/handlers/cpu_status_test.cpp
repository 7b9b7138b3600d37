// 06 01 CPU UNIT STATUS READ through full frames (W342 5-3-17; NX: W596 2-2).
#include <gtest/gtest.h>

#include <chrono>

#include "plc/profile.hpp"
#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

const std::string spaces16 = "20 20 20 20 20 20 20 20 20 20 20 20 20 20 20 20";

TEST(CpuUnitStatusRead, W342_5_3_17_IdleCpuInRunMode) {
    Harness h;
    auto r = h.send("0601");
    EXPECT_EQ(r.end_code(), 0x0000);
    // running + battery present, RUN, no errors, no messages, code 0000, 16 spaces.
    EXPECT_EQ(r.data_hex(), "05 04 00 00 00 00 00 00 00 00 " + spaces16);
}

TEST(CpuUnitStatusRead, W342_5_3_17_ModeByteAndRunBit) {
    Harness h;
    h.plc.set_mode(plc::OperatingMode::program);
    auto r = h.send("0601");
    EXPECT_EQ(r.data()[0], 0x04);  // stopped, battery present
    EXPECT_EQ(r.data()[1], 0x00);
    h.plc.set_mode(plc::OperatingMode::monitor);
    r = h.send("0601");
    EXPECT_EQ(r.data()[0], 0x05);
    EXPECT_EQ(r.data()[1], 0x02);
}

TEST(CpuUnitStatusRead, W342_5_3_17_NoBatteryProfileClearsBit2) {
    auto profile = plc::cj2h();
    profile.battery = false;
    Harness h(profile);
    EXPECT_EQ(h.send("0601").data()[0], 0x01);
}

TEST(CpuUnitStatusRead, W342_5_3_17_BatteryErrorIsNonFatalBit4AndFlag0040) {
    Harness h;
    h.plc.errors().set_battery_low(true, h.context.now);
    auto r = h.send("0601");
    EXPECT_EQ(r.end_code(), 0x0040);
    EXPECT_EQ(r.data_hex(), "05 04 00 00 00 10 00 00 00 F7 " + spaces16);
}

TEST(CpuUnitStatusRead, W342_5_3_17_FalsStopsTheCpuButKeepsTheMode) {
    Harness h;
    h.plc.errors().raise_fal(2, "LOW OIL", h.context.now);
    h.plc.errors().raise_fals(5, "MOTOR OVERLOAD", h.context.now);
    auto r = h.send("0601");
    EXPECT_EQ(r.end_code(), 0x00C0);  // fatal and non-fatal flags
    // stopped (bit 0 off) in RUN mode; fatal bit 6, non-fatal bit 15; code C105; message.
    EXPECT_EQ(r.data_hex(),
              "04 04 00 40 80 00 00 00 C1 05 4D 4F 54 4F 52 20 4F 56 45 52 4C 4F 41 44 20 20");
}

TEST(CpuUnitStatusRead, W342_5_3_17_MessageBitsAndFalMessage) {
    Harness h;
    h.plc.messages().set(0, "A");
    h.plc.messages().set(6, "B");
    h.plc.errors().raise_fal(0x1FF, "FAL 511", h.context.now);
    auto r = h.send("0601");
    EXPECT_EQ(r.end_code(), 0x0040);
    const auto d = r.data();
    EXPECT_EQ(d[6], 0x00);
    EXPECT_EQ(d[7], 0x41);  // MSG 0 and MSG 6
    EXPECT_EQ(d[8], 0x42);  // 42FF = FAL 511
    EXPECT_EQ(d[9], 0xFF);
    EXPECT_EQ(std::string(d.begin() + 10, d.end()), "FAL 511         ");
}

TEST(CpuUnitStatusRead, W342_5_3_17_ParametersAre1001) {
    Harness h;
    EXPECT_EQ(h.send("0601 00").end_code(), 0x1001);
}

TEST(CpuUnitStatusRead, W596_2_2_NxFixedValues) {
    const auto* nx = plc::find_profile("nx102");
    ASSERT_NE(nx, nullptr);
    Harness h(*nx);
    h.plc.messages().set(1, "IGNORED");
    auto r = h.send("0601");
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "01 04 00 00 00 00 00 00 00 00 " + spaces16);
    h.plc.errors().set_battery_low(true, h.context.now);  // a minor fault
    r = h.send("0601");
    EXPECT_EQ(r.data_hex(), "01 04 00 00 00 01 00 00 00 00 " + spaces16);
    h.plc.errors().raise_fals(1, "MAJOR", h.context.now);  // a major fault
    r = h.send("0601");
    EXPECT_EQ(r.data_hex(), "00 04 00 01 00 01 00 00 00 00 " + spaces16);
}

}  // namespace
}  // namespace fins::test
