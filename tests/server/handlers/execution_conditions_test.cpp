// The execution conditions of W342 5-1-2, checked generically before any handler.
#include <gtest/gtest.h>

#include "fins/command_table.hpp"
#include "server/frame_builder.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::test {
namespace {

using server::Link;
using server::handlers::check_execution_conditions;

std::uint16_t check(const ExecutionConditions& c, const plc::Plc& plc,
                    NodeAddress source = client_node, Link link = Link::udp) {
    return static_cast<std::uint16_t>(check_execution_conditions(c, plc, source, link));
}

TEST(ExecutionConditions, W342_5_1_2_ModeRefusalsNameTheCurrentMode) {
    plc::Plc plc;
    ExecutionConditions c;
    c.run = false;
    EXPECT_EQ(check(c, plc), 0x2206);
    plc.set_mode(plc::OperatingMode::monitor);
    EXPECT_EQ(check(c, plc), 0x0000);
    c.monitor = false;
    EXPECT_EQ(check(c, plc), 0x2205);
    plc.set_mode(plc::OperatingMode::program);
    EXPECT_EQ(check(c, plc), 0x0000);
    c.program = false;
    EXPECT_EQ(check(c, plc), 0x2203);
}

TEST(ExecutionConditions, W342_5_1_2_TableRowDrivesTheCheck) {
    // 03 07 PROGRAM AREA WRITE: Disabled in RUN and MONITOR, OK in PROGRAM.
    const CommandInfo* info = find_command(CommandCode{0x03, 0x07});
    ASSERT_NE(info, nullptr);
    plc::Plc plc;
    EXPECT_EQ(check(info->conditions, plc), 0x2206);
    plc.set_mode(plc::OperatingMode::monitor);
    EXPECT_EQ(check(info->conditions, plc), 0x2205);
    plc.set_mode(plc::OperatingMode::program);
    EXPECT_EQ(check(info->conditions, plc), 0x0000);
}

TEST(ExecutionConditions, W342_5_1_2_AccessRightHeldByAnotherNodeIs3001) {
    plc::Plc plc;
    ExecutionConditions c;
    c.access_right_elsewhere = false;
    EXPECT_EQ(check(c, plc), 0x0000);
    plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    EXPECT_EQ(check(c, plc), 0x3001);
    plc.set_access_right_holder(client_node);  // the holder itself may
    EXPECT_EQ(check(c, plc), 0x0000);
}

TEST(ExecutionConditions, W342_5_1_2_ProtectionsMapToTheirEndCodes) {
    plc::Plc plc;
    ExecutionConditions c;
    c.um_read_protected = false;
    c.dip_write_protected = false;
    c.network_write_protected = false;
    EXPECT_EQ(check(c, plc), 0x0000);
    plc.set_dip_write_protection(true);
    EXPECT_EQ(check(c, plc), 0x2101);
    plc.set_um_read_protection(true);
    EXPECT_EQ(check(c, plc), 0x2002);
    plc.set_network_write_protection(true);
    EXPECT_EQ(check(c, plc), 0x2102);
}

TEST(ExecutionConditions, W342_5_1_2_ModeIsCheckedFirst) {
    plc::Plc plc;
    plc.set_network_write_protection(true);
    plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    ExecutionConditions c{false, false, false, false, false, false, false};
    EXPECT_EQ(check(c, plc), 0x2206);
    c.run = true;
    EXPECT_EQ(check(c, plc), 0x2102);
    c.network_write_protected = true;
    EXPECT_EQ(check(c, plc), 0x3001);
}

// Choice: network write protection (W342 5-1-2 note 5) covers requests that arrived
// over a network; Link::local requests (in-process) are not refused.
TEST(ExecutionConditions, W342_5_1_2_Note5_LocalRequestsAreNotNetworkProtected) {
    plc::Plc plc;
    plc.set_network_write_protection(true);
    ExecutionConditions c;
    c.network_write_protected = false;
    EXPECT_EQ(check(c, plc, client_node, Link::tcp), 0x2102);
    EXPECT_EQ(check(c, plc, client_node, Link::local), 0x0000);
}

TEST(ExecutionConditions, W342_5_1_1_Note1_WriteCommandsAre2102UnderNetworkProtection) {
    Harness h;
    h.plc.set_network_write_protection(true);
    EXPECT_EQ(h.send("0102 82000000 0001 1234").end_code(), 0x2102);
    EXPECT_EQ(h.send("0103 82000000 0001 1234").end_code(), 0x2102);
    EXPECT_EQ(h.send("0105 82000000 82001000 0001").end_code(), 0x2102);
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0);
    EXPECT_EQ(h.send("0101 82000000 0001").end_code(), 0x0000);
    EXPECT_EQ(h.send("0104 82000000").end_code(), 0x0000);
    h.context.link = Link::local;
    EXPECT_EQ(h.send("0102 82000000 0001 1234").end_code(), 0x0000);
}

TEST(ExecutionConditions, W342_5_3_2_IoMemoryIsAccessibleInEveryModeAndUnderAccessRight) {
    Harness h;
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    h.plc.set_um_read_protection(true);
    h.plc.set_dip_write_protection(true);
    for (auto mode :
         {plc::OperatingMode::run, plc::OperatingMode::monitor, plc::OperatingMode::program}) {
        h.plc.set_mode(mode);
        EXPECT_EQ(h.send("0101 82000000 0001").end_code(), 0x0000);
        EXPECT_EQ(h.send("0102 82000000 0001 1234").end_code(), 0x0000);
        EXPECT_EQ(h.send("0103 82000000 0001 1234").end_code(), 0x0000);
        EXPECT_EQ(h.send("0104 82000000").end_code(), 0x0000);
        EXPECT_EQ(h.send("0105 82000000 82001000 0001").end_code(), 0x0000);
    }
}

}  // namespace
}  // namespace fins::test
