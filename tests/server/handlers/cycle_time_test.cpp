// CYCLE TIME READ 06 20 through the dispatcher with full frames (W342 5-3-18 and its
// 5-1-2 row): read, initialize, the PROGRAM-mode refusal, parameter and length errors.
// Time is injected through the harness's request context.
#include <chrono>

#include <gtest/gtest.h>

#include "fins/commands/status.hpp"
#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

using std::chrono::milliseconds;

class CycleTime : public ::testing::Test {
  protected:
    CycleTime() {
        h.context.now = t0;
        EXPECT_EQ(h.send("0620 01").end_code(), 0x0000);  // power-on: operation starts
    }
    CycleTimes read() {
        const auto r = h.send("0620 01");
        EXPECT_EQ(r.end_code(), 0x0000);
        const auto decoded = CycleTimeRead{CycleTimeOperation::read}.decode_response(r.data());
        EXPECT_TRUE(decoded && decoded->times);
        return decoded && decoded->times ? *decoded->times : CycleTimes{};
    }
    const plc::TimePoint t0{std::chrono::hours{24 * 365 * 54}};
    Harness h;
};

TEST_F(CycleTime, W342_5_3_18_ReadGivesAverageMaximumMinimumIn100us) {
    h.context.now = t0 + milliseconds(500);
    const auto t = read();
    const auto base = static_cast<std::uint32_t>(plc::ScanCycle::base_cycle(h.plc.profile()));
    EXPECT_EQ(t, h.plc.scan_cycle().times(h.context.now));
    // Cycle times stay within the jitter of the profile's base (0.1 ms units).
    EXPECT_GE(t.minimum, base - 2);
    EXPECT_LE(t.maximum, base + 3);
    EXPECT_GE(t.average, t.minimum);
    EXPECT_LE(t.average, t.maximum);
    EXPECT_EQ(h.send("0620 01").data().size(), 12U);
}

TEST_F(CycleTime, W342_5_3_18_SameTimeSameAnswer) {
    h.context.now = t0 + milliseconds(250);
    const auto a = h.send("0620 01").data();
    Harness other;
    other.context.now = t0;
    other.send("0620 01");
    other.context.now = t0 + milliseconds(250);
    EXPECT_EQ(other.send("0620 01").data(), a);
}

TEST_F(CycleTime, W342_5_3_18_InitializeRestartsMaximumAndMinimum) {
    h.context.now = t0 + milliseconds(500);
    ASSERT_NE(read().maximum, 0U);
    const auto r = h.send("0620 00");
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_TRUE(r.data().empty());  // end code only
    const auto just_after = read();
    EXPECT_EQ(just_after.maximum, 0U);
    EXPECT_EQ(just_after.minimum, 0U);
    EXPECT_NE(just_after.average, 0U);  // the last 8 cycles are still remembered
    h.context.now = t0 + milliseconds(600);
    EXPECT_NE(read().maximum, 0U);
}

TEST_F(CycleTime, W342_5_1_2_RefusedInProgramModeAcceptedInMonitor) {
    h.plc.set_mode(plc::OperatingMode::program);
    EXPECT_EQ(h.send("0620 01").end_code(), 0x2203);
    EXPECT_EQ(h.send("0620 00").end_code(), 0x2203);
    h.plc.set_mode(plc::OperatingMode::monitor);
    EXPECT_EQ(h.send("0620 01").end_code(), 0x0000);
}

TEST_F(CycleTime, W342_5_1_2_AcceptedUnderEveryProtection) {
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    h.plc.set_network_write_protection(true);
    h.plc.set_um_read_protection(true);
    h.plc.set_dip_write_protection(true);
    EXPECT_EQ(h.send("0620 01").end_code(), 0x0000);
    EXPECT_EQ(h.send("0620 00").end_code(), 0x0000);
}

TEST_F(CycleTime, W342_5_3_18_OtherParameterIs110CAndLengthsAre1002And1001) {
    EXPECT_EQ(h.send("0620 02").end_code(), 0x110C);
    EXPECT_EQ(h.send("0620 FF").end_code(), 0x110C);
    EXPECT_EQ(h.send("0620").end_code(), 0x1002);
    EXPECT_EQ(h.send("0620 01 00").end_code(), 0x1001);
}

}  // namespace
}  // namespace fins::test
