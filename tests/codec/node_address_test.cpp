// Frames section 2, automatic generation of node addresses: the node an IP address
// implies, from the address bytes alone (the codec has no socket library).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "fins/node_address.hpp"

namespace {

using fins::node_from_ip;

TEST(NodeFromIp, Frames2_Ipv4LastOctet) {
    EXPECT_EQ(node_from_ip(std::array<std::uint8_t, 4>{192, 168, 250, 10}), 10);
    EXPECT_EQ(node_from_ip(std::array<std::uint8_t, 4>{10, 0, 0, 254}), 254);
}

// Loopback follows the same rule (W420 5-2, as a plant's units bound to 127.0.N.M are
// node M): 127.0.0.9 was node 1 before, and fins-bridge addressed every unit as node 1.
TEST(NodeFromIp, Frames2_LoopbackLastOctetToo) {
    EXPECT_EQ(node_from_ip(std::array<std::uint8_t, 4>{127, 0, 0, 1}), 1);
    EXPECT_EQ(node_from_ip(std::array<std::uint8_t, 4>{127, 0, 0, 9}), 9);
    EXPECT_EQ(node_from_ip(std::array<std::uint8_t, 4>{127, 0, 1, 5}), 5);
    std::array<std::uint8_t, 16> v6_loopback{};
    v6_loopback[15] = 1;
    EXPECT_EQ(node_from_ip(v6_loopback), 1);
}

TEST(NodeFromIp, Frames2_Ipv4MappedIpv6UsesTheIpv4Rule) {
    std::array<std::uint8_t, 16> mapped{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF, 192, 168, 0, 7};
    EXPECT_EQ(node_from_ip(mapped), 7);
    mapped[12] = 127;
    mapped[15] = 3;
    EXPECT_EQ(node_from_ip(mapped), 3);
}

TEST(NodeFromIp, Frames2_OtherIpv6LastByte) {
    std::array<std::uint8_t, 16> link_local{0xFE, 0x80};
    link_local[14] = 0x00;
    link_local[15] = 0x12;
    EXPECT_EQ(node_from_ip(link_local), 0x12);
}

TEST(NodeFromIp, WrongLengthIsNoNode) {
    EXPECT_EQ(node_from_ip(std::array<std::uint8_t, 5>{127, 0, 0, 1, 0}), 0);
    EXPECT_EQ(node_from_ip(std::span<const std::uint8_t>{}), 0);
}

}  // namespace
