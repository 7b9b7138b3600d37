// Network write protection "global or for listed nodes" (W342 5-1-2 note 5, W596 2-5)
// through whole request frames: the source address of the request header decides.
#include <array>

#include <gtest/gtest.h>

#include "fins/command_table.hpp"
#include "server/frame_builder.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::test {
namespace {

using plc::NetworkWriteProtection;
using server::Link;

constexpr const char* write_d0 = "0102 82000000 0001 1234";
constexpr const char* fill_d0 = "0103 82000000 0001 5678";
constexpr const char* transfer = "0105 82000000 82001000 0001";
constexpr const char* read_d0 = "0101 82000000 0001";

FrameFields from(std::uint8_t network, std::uint8_t node, std::uint8_t unit = 0) {
    FrameFields f;
    f.source = NodeAddress{network, node, unit};
    return f;
}

void protect(Harness& h, NetworkWriteProtection mode, std::vector<NodeAddress> nodes) {
    h.plc.set_network_write_protection_setting({mode, std::move(nodes)});
}

TEST(NetworkWriteProtection, OffByDefault) {
    Harness h;
    EXPECT_FALSE(h.plc.network_write_protection());
    EXPECT_EQ(h.plc.network_write_protection_setting().mode, NetworkWriteProtection::off);
    EXPECT_EQ(h.send(write_d0, from(1, 20)).end_code(), 0x0000);
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0x1234);
}

TEST(NetworkWriteProtection, W342_5_1_2_Note5_GlobalRefusesEveryNetworkNode) {
    Harness h;
    protect(h, NetworkWriteProtection::all, {});
    for (auto link : {Link::udp, Link::tcp}) {
        h.context.link = link;
        for (const std::uint8_t node : std::array<std::uint8_t, 3>{1, 20, 254}) {
            EXPECT_EQ(h.send(write_d0, from(0, node)).end_code(), 0x2102);
            EXPECT_EQ(h.send(fill_d0, from(1, node)).end_code(), 0x2102);
            EXPECT_EQ(h.send(transfer, from(1, node)).end_code(), 0x2102);
            EXPECT_EQ(h.send(read_d0, from(1, node)).end_code(), 0x0000);  // reads are not writes
        }
    }
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0);
    h.context.link = Link::local;  // not "via a network"
    EXPECT_EQ(h.send(write_d0, from(1, 20)).end_code(), 0x0000);
}

// The bool API (the control channel's switch) means "all nodes" and keeps the list.
TEST(NetworkWriteProtection, BoolSwitchIsAllNodesAndKeepsTheList) {
    Harness h;
    protect(h, NetworkWriteProtection::listed, {NodeAddress{1, 30, 0}});
    h.plc.set_network_write_protection(true);
    EXPECT_EQ(h.plc.network_write_protection_setting().mode, NetworkWriteProtection::all);
    EXPECT_TRUE(h.plc.network_write_protection());
    EXPECT_EQ(h.send(write_d0, from(1, 20)).end_code(), 0x2102);
    h.plc.set_network_write_protection(false);
    EXPECT_FALSE(h.plc.network_write_protection());
    EXPECT_EQ(h.send(write_d0, from(1, 20)).end_code(), 0x0000);
    ASSERT_EQ(h.plc.network_write_protection_setting().nodes.size(), 1u);
}

// Choice: "listed" refuses only the listed nodes (note 5: "FINS write commands from
// specified network nodes"); the others write freely.
TEST(NetworkWriteProtection, W342_5_1_2_Note5_ListedRefusesOnlyTheListedNodes) {
    Harness h;
    protect(h, NetworkWriteProtection::listed, {NodeAddress{1, 20, 0}, NodeAddress{2, 0xFF, 0}});
    EXPECT_TRUE(h.plc.network_write_protection());
    EXPECT_EQ(h.send(write_d0, from(1, 20)).end_code(), 0x2102);
    EXPECT_EQ(h.send(write_d0, from(1, 20, 0xFE)).end_code(), 0x2102);  // unit ignored
    EXPECT_EQ(h.send(fill_d0, from(2, 7)).end_code(), 0x2102);          // 2.* = all of net 2
    EXPECT_EQ(h.send(fill_d0, from(2, 254)).end_code(), 0x2102);
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0);
    EXPECT_EQ(h.send(write_d0, from(1, 21)).end_code(), 0x0000);
    EXPECT_EQ(h.send(write_d0, from(0, 20)).end_code(), 0x0000);  // another network number
    EXPECT_EQ(h.send(transfer, from(3, 20)).end_code(), 0x0000);
    EXPECT_EQ(h.memory().words(Region::dm)[16], 0x1234);  // D0 -> D16
    EXPECT_EQ(h.send(read_d0, from(1, 20)).end_code(), 0x0000);
}

// The CS/CJ PLC Setup form: protection on, the listed nodes excluded from it.
TEST(NetworkWriteProtection, AllExceptListedLetsOnlyTheListedNodesWrite) {
    Harness h;
    protect(h, NetworkWriteProtection::all_except_listed, {NodeAddress{1, 20, 0}});
    EXPECT_EQ(h.send(write_d0, from(1, 20)).end_code(), 0x0000);
    EXPECT_EQ(h.send(write_d0, from(1, 21)).end_code(), 0x2102);
    EXPECT_EQ(h.send(write_d0, from(0, 20)).end_code(), 0x2102);
    protect(h, NetworkWriteProtection::all_except_listed, {});  // an empty list = all
    EXPECT_EQ(h.send(write_d0, from(1, 20)).end_code(), 0x2102);
}

// 09 20 under protection for listed nodes: the reads pass for everyone (5-3-21,
// 5-3-23); MESSAGE CLEAR is refused for a listed node only, and only it is logged.
TEST(NetworkWriteProtection, W342_5_3_21_MessageReadsPassMessageClearFollowsTheSource) {
    Harness h;
    h.plc.messages().set(0, "A");
    protect(h, NetworkWriteProtection::listed, {NodeAddress{1, 20, 0}});
    EXPECT_EQ(h.send("0920 0001", from(1, 20)).end_code(), 0x0000);
    EXPECT_EQ(h.send("0920 8001", from(1, 20)).end_code(), 0x0000);
    EXPECT_EQ(h.send("0920 4001", from(1, 20)).end_code(), 0x2102);
    EXPECT_EQ(h.plc.messages().present(), 0x01);
    EXPECT_EQ(h.plc.write_access_log().size(), 0u);
    EXPECT_EQ(h.send("0920 4001", from(1, 21)).end_code(), 0x0000);
    EXPECT_EQ(h.plc.messages().present(), 0x00);
    ASSERT_EQ(h.plc.write_access_log().size(), 1u);
    EXPECT_EQ(h.plc.write_access_log().at(0).source, (NodeAddress{1, 21, 0}));
}

TEST(NetworkWriteProtection, AtMost32NodesAreKept) {
    Harness h;
    std::vector<NodeAddress> nodes;
    for (std::uint8_t n = 1; n <= 40; ++n)
        nodes.push_back(NodeAddress{1, n, 0});
    protect(h, NetworkWriteProtection::listed, nodes);
    EXPECT_EQ(h.plc.network_write_protection_setting().nodes.size(), plc::max_protection_nodes);
    EXPECT_EQ(h.send(write_d0, from(1, 32)).end_code(), 0x2102);
    EXPECT_EQ(h.send(write_d0, from(1, 33)).end_code(), 0x0000);
}

// Every command the 5-1-2 table marks "Disabled" under network protection is refused
// for a listed node and for no other; the rest pass.
TEST(NetworkWriteProtection, W342_5_1_2_TableRowsFollowTheSource) {
    plc::Plc plc;
    plc.set_network_write_protection_setting(
        {NetworkWriteProtection::listed, {NodeAddress{1, 20, 0}}});
    int disabled = 0;
    for (const auto& info : command_table()) {
        const auto expected_listed = info.conditions.network_write_protected ? 0x0000 : 0x2102;
        ExecutionConditions c = info.conditions;
        c.run = c.monitor = c.program = true;  // isolate the protection check
        c.access_right_elsewhere = c.um_read_protected = c.dip_write_protected = true;
        const auto check = [&](NodeAddress source) {
            return static_cast<int>(
                server::handlers::check_execution_conditions(c, plc, source, Link::udp));
        };
        EXPECT_EQ(check(NodeAddress{1, 20, 0}), expected_listed) << info.name;
        EXPECT_EQ(check(NodeAddress{1, 21, 0}), 0x0000) << info.name;
        disabled += info.conditions.network_write_protected ? 0 : 1;
    }
    EXPECT_GT(disabled, 10);
}

}  // namespace
}  // namespace fins::test
