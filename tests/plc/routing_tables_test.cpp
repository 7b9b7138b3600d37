// The 8013 word layout of the routing tables (plc/routing_tables.hpp; README "The 8013
// routing-table layout"): encode/decode round trip, "none", and every broken case.
#include "plc/routing_tables.hpp"

#include <array>
#include <vector>

#include <gtest/gtest.h>

namespace fins::plc {
namespace {

std::vector<std::uint16_t> area() {
    return std::vector<std::uint16_t>(0x200, 0);
}

RoutingTables sample() {
    RoutingTables t;
    t.gateway_count = 0x07;
    t.local[0] = {1, 0};
    t.local[1] = {2, 1};
    t.local_count = 2;
    t.relay[0] = {3, 2, 2};
    t.relay_count = 1;
    return t;
}

TEST(RoutingTables, EncodesTheDocumentedWordsAndDecodesThemBack) {
    auto words = area();
    encode_routing_tables(sample(), words);
    EXPECT_EQ(words[0], 0x0007);
    EXPECT_EQ(words[1], 0x0100);
    EXPECT_EQ(words[2], 0x0201);
    EXPECT_EQ(words[0x11], 0x0302);
    EXPECT_EQ(words[0x12], 0x0002);
    const auto d = decode_routing_tables(words);
    ASSERT_EQ(d.state, RoutingTablesState::valid);
    EXPECT_EQ(d.tables.gateway_count, 0x07);
    ASSERT_NE(d.tables.find_local(2), nullptr);
    EXPECT_EQ(d.tables.find_local(2)->unit, 1);
    ASSERT_NE(d.tables.find_relay(3), nullptr);
    EXPECT_EQ(*d.tables.find_relay(3), (RelayNetwork{3, 2, 2}));
    EXPECT_EQ(d.tables.find_relay(4), nullptr);
}

TEST(RoutingTables, W342_5_3_9_AClearedAreaHasNoRoutingTables) {
    auto words = area();
    EXPECT_EQ(decode_routing_tables(words).state, RoutingTablesState::none);
    words[0] = 0x0007;  // an option alone is no table
    EXPECT_EQ(decode_routing_tables(words).state, RoutingTablesState::none);
    EXPECT_EQ(decode_routing_tables(std::span<const std::uint16_t>(words).first(10)).state,
              RoutingTablesState::none);
}

TEST(RoutingTables, UnusedEntriesMayLieBetweenUsedOnes) {
    auto words = area();
    words[5] = 0x0203;
    words[0x11 + 2 * 7] = 0x0902;
    words[0x11 + 2 * 7 + 1] = 0x0011;
    const auto d = decode_routing_tables(words);
    ASSERT_EQ(d.state, RoutingTablesState::valid);
    EXPECT_EQ(d.tables.gateway_count, 0x02);  // option 00 = 02
    EXPECT_EQ(*d.tables.find_relay(9), (RelayNetwork{9, 2, 0x11}));
}

TEST(RoutingTables, BrokenEntriesMakeTheWholeTableBroken) {
    struct Case {
        std::size_t word;
        std::uint16_t value;
    };
    const std::array<Case, 11> cases{{
        {0x0000, 0x0003},  // GCT option neither 02 nor 07
        {0x0000, 0x0102},  // option high byte
        {0x0003, 0x0005},  // network 00 with a unit
        {0x0003, 0x8001},  // network above 7F
        {0x0003, 0x0310},  // unit above 0F
        {0x0003, 0x0105},  // network 1 listed twice
        {0x0013, 0x0402},  // relay node 00 (second word 0000 with a first word)
        {0x0013, 0x0405},  // relay network 5 is not local
        {0x0013, 0x0102},  // relay entry for a local network
        {0x0013, 0x0302},  // network 3 listed twice in the relay table
        {0x0014, 0x0102},  // second word's high byte set
    }};
    for (const auto& c : cases) {
        auto words = area();
        encode_routing_tables(sample(), words);
        words[c.word] = c.value;
        if (c.word == 0x0013 && c.value != 0x0402) words[0x14] = 0x0003;
        EXPECT_EQ(decode_routing_tables(words).state, RoutingTablesState::broken)
            << std::hex << c.word << " = " << c.value;
    }
}

}  // namespace
}  // namespace fins::plc
