// 0C 01 .. 0C 03 through full frames, and the access right across nodes and commands
// (W342 5-3-24 .. 5-3-26, 5-1-2 "Access right" column).
#include <gtest/gtest.h>

#include <array>

#include "fins/command_table.hpp"
#include "server/frame_builder.hpp"
#include "server/handlers/handlers.hpp"

namespace fins::test {
namespace {

constexpr NodeAddress other_node{0x02, 0x63, 0x10};

FrameFields from(const NodeAddress& source) {
    FrameFields f;
    f.source = source;
    return f;
}

TEST(AccessRightAcquire, W342_5_3_24_AcquiresForTheRequesterAndAgain) {
    Harness h;
    EXPECT_EQ(h.send("0C01 FFFF").end_code(), 0x0000);
    ASSERT_TRUE(h.plc.access_right_holder().has_value());
    EXPECT_EQ(*h.plc.access_right_holder(), client_node);
    EXPECT_EQ(h.send("0C01 FFFF").end_code(), 0x0000);  // the holder may acquire again
}

TEST(AccessRightAcquire, W342_5_3_24_HeldElsewhereAnswers3001) {
    Harness h;
    h.plc.set_access_right_holder(other_node);
    auto r = h.send("0C01 FFFF");
    EXPECT_EQ(r.end_code(), 0x3001);
    EXPECT_EQ(*h.plc.access_right_holder(), other_node);
}

TEST(AccessRightAcquire, W342_5_3_24_HeldElsewhereAnswers3001WithHolder) {
    // The holder (unit, node, network; frames 6/0C01) follows 3001: the command table
    // lets the 0C 01 handler run while another node holds the right so it can say who.
    Harness h;
    h.plc.set_access_right_holder(other_node);
    auto r = h.send("0C01 FFFF");
    EXPECT_EQ(r.end_code(), 0x3001);
    EXPECT_EQ(r.data_hex(), "10 63 02");
}

TEST(AccessRightAcquire, W342_5_3_24_HandlerWritesTheHolderAfter3001) {
    // The handler on its own (no execution-condition check in front of it).
    plc::Plc plc;
    plc.set_access_right_holder(other_node);
    Header header;
    header.source = client_node;
    const server::RequestContext request{};
    server::handlers::HandlerContext context{plc, header, request};
    const auto* entry = server::handlers::find_handler(CommandCode{0x0C, 0x01});
    ASSERT_NE(entry, nullptr);
    std::array<std::uint8_t, 16> buffer{};
    ByteWriter out(buffer);
    const std::array<std::uint8_t, 2> parameters{0xFF, 0xFF};
    EXPECT_EQ(entry->function(context, parameters, out), EndCode::no_access_right);
    EXPECT_TRUE(context.keep_data);
    EXPECT_EQ(to_hex(out.written()), "10 63 02");  // unit, node, network
    EXPECT_EQ(*plc.access_right_holder(), other_node);
}

TEST(AccessRight, W342_5_1_3_ProgramNumberOtherThanFFFFIs1106) {
    Harness h;
    for (const char* command : {"0C01 0000", "0C02 FFFE", "0C03 0001"})
        EXPECT_EQ(h.send(command).end_code(), 0x1106) << command;
    EXPECT_FALSE(h.plc.access_right_holder().has_value());
    EXPECT_EQ(h.send("0C01 FF").end_code(), 0x1002);
    EXPECT_EQ(h.send("0C02 FFFF00").end_code(), 0x1001);
}

TEST(AccessRightForcedAcquire, W342_5_3_25_TakesTheRightFromAnotherNode) {
    Harness h;
    h.plc.set_access_right_holder(other_node);
    EXPECT_EQ(h.send("0C02 FFFF").end_code(), 0x0000);
    EXPECT_EQ(*h.plc.access_right_holder(), client_node);
    // Now the former holder is the one refused.
    EXPECT_EQ(h.send("0C01 FFFF", from(other_node)).end_code(), 0x3001);
}

TEST(AccessRightRelease, W342_5_3_26_ReleasesWhoeverHoldsItAndIsNormalWhenNobodyDoes) {
    Harness h;
    h.plc.set_access_right_holder(other_node);
    EXPECT_EQ(h.send("0C03 FFFF").end_code(), 0x0000);
    EXPECT_FALSE(h.plc.access_right_holder().has_value());
    EXPECT_EQ(h.send("0C03 FFFF").end_code(), 0x0000);
}

TEST(AccessRight, W342_5_1_2_DisabledCommandsAre3001ForOtherNodesOnly) {
    Harness h;
    h.plc.set_mode(plc::OperatingMode::monitor);
    ASSERT_EQ(h.send("0C01 FFFF", from(other_node)).end_code(), 0x0000);
    // "No" in the access-right column: refused to us, accepted from the holder.
    for (const char* command : {"0401 FFFF", "0402 FFFF", "2101 FFFE", "2141", "0C01 FFFF"}) {
        EXPECT_EQ(h.send(command).end_code(), 0x3001) << command;
    }
    EXPECT_EQ(h.send("2141", from(other_node)).end_code(), 0x0000);
    // "Yes": accepted from every node.
    for (const char* command : {"0101 82000000 0001", "0102 82000000 0001 1234", "0601",
                                "2102 0000 0000", "2140 0000 0000", "0C02 FFFF"}) {
        EXPECT_EQ(h.send(command).end_code() & 0x7F3F, 0x0000) << command;
    }
    // 0C 02 made us the holder: the other node is refused now, and 0C 03 frees everyone.
    EXPECT_EQ(h.send("2141", from(other_node)).end_code(), 0x3001);
    EXPECT_EQ(h.send("0C03 FFFF", from(other_node)).end_code(), 0x0000);
    EXPECT_EQ(h.send("2141", from(other_node)).end_code(), 0x0000);
}

TEST(AccessRight, W342_5_3_24_HolderIsTheFullSourceAddress) {
    Harness h;
    ASSERT_EQ(h.send("0C01 FFFF").end_code(), 0x0000);
    // Same node number, another unit address: another device.
    const NodeAddress other_unit{client_node.network, client_node.node, 0x01};
    EXPECT_EQ(h.send("2141", from(other_unit)).end_code(), 0x3001);
}

}  // namespace
}  // namespace fins::test
