// 09 20 MESSAGE READ / MESSAGE CLEAR / FAL/FALS READ through full frames
// (W342 5-3-21 .. 5-3-23, 5-1-2 "Disabled (MESSAGE CLEAR only)"; the reads are
// allowed under network write protection, 5-3-21 / 5-3-23).
#include <gtest/gtest.h>

#include <string>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

std::string text_hex(const std::string& s, std::size_t width) {
    std::string padded = s + std::string(width - s.size(), ' ');
    return to_hex(Bytes(reinterpret_cast<const std::uint8_t*>(padded.data()), padded.size()));
}

TEST(MessageRead, W342_5_3_21_AscendingThirtyTwoBytesSpacesForUnregistered) {
    Harness h;
    h.plc.messages().set(1, "TANK FULL");
    h.plc.messages().set(7, "DOOR OPEN");
    auto r = h.send("0920 0083");  // MSG 0, 1, 7
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "00 83 " + text_hex("", 32) + " " + text_hex("TANK FULL", 32) + " " +
                                text_hex("DOOR OPEN", 32));
}

TEST(MessageRead, W342_5_3_21_NoBitsNoData) {
    Harness h;
    h.plc.messages().set(1, "X");
    auto r = h.send("0920 0000");
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "00 00");
}

TEST(MessageRead, W342_5_3_21_AllEightFitInOneResponse) {
    Harness h;
    auto r = h.send("0920 00FF");
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data().size(), 2u + 8u * 32u);
}

TEST(MessageRead, W342_5_3_21_StrayBitsAndUnknownVariantAre110C) {
    Harness h;
    EXPECT_EQ(h.send("0920 0100").end_code(), 0x110C);
    EXPECT_EQ(h.send("0920 4100").end_code(), 0x110C);
    EXPECT_EQ(h.send("0920 C000").end_code(), 0x110C);
    EXPECT_EQ(h.send("0920 00").end_code(), 0x1002);
    EXPECT_EQ(h.send("0920 000100").end_code(), 0x1001);
}

TEST(MessageClear, W342_5_3_22_ClearsTheSelectedMessages) {
    Harness h;
    h.plc.messages().set(0, "A");
    h.plc.messages().set(1, "B");
    h.plc.messages().set(2, "C");
    auto r = h.send("0920 4005");  // clear 0 and 2
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_TRUE(r.data().empty());
    EXPECT_EQ(h.plc.messages().present(), 0x02);
    EXPECT_EQ(h.send("0920 4080").end_code(), 0x0000);  // not registered: still normal
}

TEST(MessageClear, W342_5_1_2_RefusedWhileAnotherNodeHoldsTheAccessRightReadIsNot) {
    Harness h;
    h.plc.messages().set(3, "KEEP");
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    EXPECT_EQ(h.send("0920 4008").end_code(), 0x3001);
    EXPECT_EQ(h.plc.messages().present(), 0x08);
    EXPECT_EQ(h.send("0920 0008").end_code(), 0x0000);  // MESSAGE READ
    EXPECT_EQ(h.send("0920 8001").end_code(), 0x0000);  // FAL/FALS READ
    // The holder itself may clear.
    h.plc.set_access_right_holder(client_node);
    EXPECT_EQ(h.send("0920 4008").end_code(), 0x0000);
    EXPECT_EQ(h.plc.messages().present(), 0x00);
}

// 5-3-21 and 5-3-23: MESSAGE READ and FAL/FALS READ are "OK" under network write
// protection; MESSAGE CLEAR stays refused (5-1-2 "Disabled") and nothing is cleared.
TEST(MessageRead, W342_5_3_21_And_5_3_23_ReadsAreAllowedUnderNetworkWriteProtection) {
    Harness h;
    h.plc.messages().set(0, "HELLO");
    h.plc.set_network_write_protection(true);
    const auto read = h.send("0920 0001");
    EXPECT_EQ(read.end_code(), 0x0000);
    EXPECT_EQ(read.data_hex(), "00 01 " + text_hex("HELLO", 32));
    EXPECT_EQ(h.send("0920 8001").end_code(), 0x0000);
    EXPECT_EQ(h.send("0920 4001").end_code(), 0x2102);
    EXPECT_EQ(h.plc.messages().present(), 0x01);
    // Network write protection comes first, as in the execution conditions.
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    EXPECT_EQ(h.send("0920 4001").end_code(), 0x2102);
    // A local (in-process) request is not one "via networks" (5-1-2 note 5).
    h.plc.set_access_right_holder(std::nullopt);
    h.context.link = server::Link::local;
    EXPECT_EQ(h.send("0920 4001").end_code(), 0x0000);
    EXPECT_EQ(h.plc.messages().present(), 0x00);
}

// 5-3-30 logs FINS write commands: MESSAGE CLEAR is one, the two reads are not.
TEST(MessageRead, W342_5_3_30_ReadsAreNotInTheWriteAccessLogClearIs) {
    Harness h;
    ASSERT_EQ(h.send("0920 0001").end_code(), 0x0000);
    ASSERT_EQ(h.send("0920 8001").end_code(), 0x0000);
    EXPECT_EQ(h.plc.write_access_log().size(), 0u);
    ASSERT_EQ(h.send("0920 4001").end_code(), 0x0000);
    ASSERT_EQ(h.plc.write_access_log().size(), 1u);
    EXPECT_EQ(h.plc.write_access_log().at(0).command, (CommandCode{0x09, 0x20}));
}

TEST(FalFalsRead, W342_5_3_23_MessageOfThePresentError) {
    Harness h;
    h.plc.errors().raise_fal(5, "LOW PRESSURE", h.context.now);
    auto r = h.send("0920 8005");
    EXPECT_EQ(r.end_code(), 0x0040);  // FAL 5 is a non-fatal error
    EXPECT_EQ(r.data_hex(), "80 05 " + text_hex("LOW PRESSURE", 16));
    h.plc.errors().raise_fals(5, "STOP", h.context.now);
    r = h.send("0920 8005");
    EXPECT_EQ(r.end_code(), 0x00C0);
    EXPECT_EQ(r.data_hex(), "80 05 " + text_hex("STOP", 16));
}

TEST(FalFalsRead, W342_5_3_23_NoMessageRegisteredIsSixteenSpaces) {
    Harness h;
    auto r = h.send("0920 81FF");
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "81 FF " + text_hex("", 16));
}

TEST(FalFalsRead, W342_5_3_23_NumberOutsideOneTo511Is110C) {
    Harness h;
    EXPECT_EQ(h.send("0920 8000").end_code(), 0x110C);
    EXPECT_EQ(h.send("0920 8200").end_code(), 0x110C);
    EXPECT_EQ(h.send("0920 BFFF").end_code(), 0x110C);
}

}  // namespace
}  // namespace fins::test
