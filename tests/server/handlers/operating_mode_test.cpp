// RUN 04 01 and STOP 04 02 through the dispatcher with full frames (W342 5-3-13,
// 5-3-14, execution conditions of 5-1-2): every variant, every end code the sections
// name, and the scan cycle following the mode.
#include <chrono>

#include <gtest/gtest.h>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

using plc::OperatingMode;
using std::chrono::milliseconds;

class OperatingModeTest : public ::testing::Test {
  protected:
    OperatingModeTest() { h.context.now = plc::TimePoint{std::chrono::hours{24 * 365 * 54}}; }
    std::uint16_t send(std::string_view command) { return h.send(command).end_code(); }
    void to_program() {
        ASSERT_EQ(send("0402"), 0x0000);
        ASSERT_EQ(h.plc.mode(), OperatingMode::program);
    }
    Harness h;
};

TEST_F(OperatingModeTest, W342_5_3_13_CommandCodeOnlyMeansMonitor) {
    to_program();
    const auto r = h.send("0401");
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_TRUE(r.data().empty());
    EXPECT_EQ(h.plc.mode(), OperatingMode::monitor);
}

TEST_F(OperatingModeTest, W342_5_3_13_ProgramNumberOnlyMeansMonitor) {
    to_program();
    EXPECT_EQ(send("0401 FFFF"), 0x0000);
    EXPECT_EQ(h.plc.mode(), OperatingMode::monitor);
}

TEST_F(OperatingModeTest, W342_5_3_13_ModeByteSelectsRunOrMonitor) {
    to_program();
    EXPECT_EQ(send("0401 FFFF 04"), 0x0000);
    EXPECT_EQ(h.plc.mode(), OperatingMode::run);
    EXPECT_EQ(send("0401 FFFF 02"), 0x0000);
    EXPECT_EQ(h.plc.mode(), OperatingMode::monitor);
    EXPECT_EQ(send("0401 FFFF 04"), 0x0000);
    EXPECT_EQ(h.plc.mode(), OperatingMode::run);
}

TEST_F(OperatingModeTest, W342_5_3_13_AlreadyInTheModeIsANormalCompletion) {
    ASSERT_EQ(h.plc.mode(), OperatingMode::run);  // power-on mode
    EXPECT_EQ(send("0401 FFFF 04"), 0x0000);
    EXPECT_EQ(h.plc.mode(), OperatingMode::run);
    to_program();
    EXPECT_EQ(send("0402"), 0x0000);
    EXPECT_EQ(send("0402 FFFF"), 0x0000);
    EXPECT_EQ(h.plc.mode(), OperatingMode::program);
}

TEST_F(OperatingModeTest, W342_5_3_13_ProgramNumberOtherThanFFFFIs1106) {
    to_program();
    EXPECT_EQ(send("0401 0000"), 0x1106);
    EXPECT_EQ(send("0401 0001 04"), 0x1106);
    EXPECT_EQ(h.plc.mode(), OperatingMode::program);
}

TEST_F(OperatingModeTest, W342_5_3_13_ModeOtherThan02Or04Is110C) {
    to_program();
    EXPECT_EQ(send("0401 FFFF 00"), 0x110C);
    EXPECT_EQ(send("0401 FFFF 01"), 0x110C);  // DEBUG exists on CV only
    EXPECT_EQ(send("0401 FFFF 03"), 0x110C);
    EXPECT_EQ(h.plc.mode(), OperatingMode::program);
}

TEST_F(OperatingModeTest, W342_5_1_3_LengthErrors) {
    EXPECT_EQ(send("0401 FF"), 0x1002);
    EXPECT_EQ(send("0401 FFFF 04 00"), 0x1001);
    EXPECT_EQ(send("0402 FF"), 0x1002);
    EXPECT_EQ(send("0402 FFFF 00"), 0x1001);
    EXPECT_EQ(h.plc.mode(), OperatingMode::run);
}

TEST_F(OperatingModeTest, W342_5_3_14_StopWithOrWithoutProgramNumber) {
    EXPECT_EQ(send("0402"), 0x0000);
    EXPECT_EQ(h.plc.mode(), OperatingMode::program);
    ASSERT_EQ(send("0401 FFFF 04"), 0x0000);
    EXPECT_EQ(send("0402 FFFF"), 0x0000);
    EXPECT_EQ(h.plc.mode(), OperatingMode::program);
    ASSERT_EQ(send("0401 FFFF 02"), 0x0000);
    EXPECT_EQ(send("0402 1234"), 0x1106);
    EXPECT_EQ(h.plc.mode(), OperatingMode::monitor);
}

TEST_F(OperatingModeTest, W342_5_1_2_AccessRightHeldElsewhereIs3001) {
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    EXPECT_EQ(send("0402"), 0x3001);
    EXPECT_EQ(send("0401 FFFF 02"), 0x3001);
    EXPECT_EQ(h.plc.mode(), OperatingMode::run);
    h.plc.set_access_right_holder(client_node);  // the holder may
    EXPECT_EQ(send("0402"), 0x0000);
}

TEST_F(OperatingModeTest, W342_5_1_2_NetworkWriteProtectionIs2102) {
    h.plc.set_network_write_protection(true);
    EXPECT_EQ(send("0402"), 0x2102);
    EXPECT_EQ(send("0401 FFFF 04"), 0x2102);
    EXPECT_EQ(h.plc.mode(), OperatingMode::run);
}

TEST_F(OperatingModeTest, W342_5_1_2_AcceptedUnderUmAndDipProtection) {
    h.plc.set_um_read_protection(true);
    h.plc.set_dip_write_protection(true);
    EXPECT_EQ(send("0402"), 0x0000);
    EXPECT_EQ(send("0401 FFFF 04"), 0x0000);
}

TEST_F(OperatingModeTest, W342_5_3_18_ScanCycleFollowsTheMode) {
    const auto t0 = h.context.now;
    EXPECT_EQ(send("0620 01"), 0x0000);  // power-on in RUN: cycles run
    h.context.now = t0 + milliseconds(100);
    const auto running = h.send("0620 01");
    ASSERT_EQ(running.end_code(), 0x0000);
    EXPECT_NE(running.data_hex(), "00 00 00 00 00 00 00 00 00 00 00 00");

    to_program();
    EXPECT_FALSE(h.plc.scan_cycle().running());
    EXPECT_EQ(send("0620 01"), 0x2203);  // 5-1-2: not in PROGRAM mode

    h.context.now = t0 + milliseconds(200);
    ASSERT_EQ(send("0401 FFFF 04"), 0x0000);
    EXPECT_TRUE(h.plc.scan_cycle().running());
    // Operation restarts at the next cycle: nothing measured yet (5-3-18 "Comments").
    EXPECT_EQ(h.send("0620 01").data_hex(), "00 00 00 00 00 00 00 00 00 00 00 00");
    h.context.now = t0 + milliseconds(300);
    EXPECT_NE(h.send("0620 01").data_hex(), "00 00 00 00 00 00 00 00 00 00 00 00");
}

TEST_F(OperatingModeTest, RunToMonitorKeepsTheProgramRunning) {
    const auto t0 = h.context.now;
    EXPECT_EQ(send("0401 FFFF 04"), 0x0000);
    h.context.now = t0 + milliseconds(100);
    EXPECT_EQ(send("0401 FFFF 02"), 0x0000);
    // A restart would have cleared the statistics (nothing measured at this instant).
    EXPECT_NE(h.plc.scan_cycle().times(h.context.now).maximum, 0U);
    EXPECT_NE(h.plc.scan_cycle().cycles(h.context.now), 0U);
}

}  // namespace
}  // namespace fins::test
