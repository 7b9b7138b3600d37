// A three-network plant (plant_fixture.hpp): a client on network 1 reaches the CJ2H on
// network 3 through two routers; each routing fault answers its W342 5-1-3 end code
// with the relay flag (bit 15) and the relay word naming the router that failed; the
// routing tables in 8013 change routing at run time (02 01 / 02 02 / 02 03).
#include <array>
#include <vector>

#include <gtest/gtest.h>

#include "fins/address.hpp"
#include "integration/support/plant_fixture.hpp"
#include "plc/routing_tables.hpp"

namespace fins::test {
namespace {

constexpr NodeAddress line_3{3, 5, 0};

Address dm(std::uint32_t word) {
    return *parse_address("D" + std::to_string(word));
}

std::vector<std::uint8_t> be16s(std::initializer_list<std::uint16_t> words) {
    std::vector<std::uint8_t> out;
    for (auto w : words) {
        out.push_back(static_cast<std::uint8_t>(w >> 8));
        out.push_back(static_cast<std::uint8_t>(w & 0xFF));
    }
    return out;
}

// 02 02 PARAMETER AREA WRITE of `data` at `word` of 8013 (not the last word).
RawResponse write_routing_words(Client& c, std::uint16_t word, std::vector<std::uint16_t> data) {
    auto params = be16s({plc::routing_table_area, word, static_cast<std::uint16_t>(data.size())});
    for (auto w : data) {
        params.push_back(static_cast<std::uint8_t>(w >> 8));
        params.push_back(static_cast<std::uint8_t>(w & 0xFF));
    }
    auto r = c.send_raw({0x02, 0x02}, params);
    EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message());
    return r ? *r : RawResponse{};
}

RawResponse read_memory(Client& c) {
    // 01 01 MEMORY AREA READ, D0, 1 word.
    auto r =
        c.send_raw({0x01, 0x01}, std::vector<std::uint8_t>{0x82, 0x00, 0x00, 0x00, 0x00, 0x01});
    EXPECT_TRUE(r.has_value()) << (r ? "" : r.error().message());
    return r ? *r : RawResponse{};
}

void expect_relay_error(const RawResponse& r, std::uint16_t code, RelayErrorSource where) {
    EXPECT_TRUE(r.code.relay_error());
    EXPECT_EQ(r.code.raw(), 0x8000 | code);
    ASSERT_TRUE(r.relay.has_value());
    EXPECT_EQ(*r.relay, where);
}

TEST(Plant, W596_2_4_ClientOnNetwork1ReadsAndWritesNetwork3ThroughTwoRouters) {
    PlantThread plant;
    for (const bool tcp : {false, true}) {
        auto c = plant.from_network_1(line_3, tcp);
        ASSERT_NE(c, nullptr);
        const std::array<std::uint16_t, 3> words{
            0x1234, static_cast<std::uint16_t>(tcp ? 0x00AA : 0x5555), 0xBEEF};
        ASSERT_TRUE(c->write_words(dm(100), words));
        const auto got = c->read_words(dm(100), 3);
        ASSERT_TRUE(got) << got.error().message();
        EXPECT_EQ(*got, std::vector<std::uint16_t>(words.begin(), words.end()));
        // The same words, asked of line-3 directly on its own network.
        auto direct = plant.client("127.0.3.5", plant.port(2), {3, 5, 0}, tcp);
        const auto same = direct->read_words(dm(100), 3);
        ASSERT_TRUE(same);
        EXPECT_EQ(*same, *got);
    }
}

TEST(Plant, W342_5_2_AnswerComesFromTheDestinationWithItsGctDecrementedOnTheWayBack) {
    PlantThread plant;
    auto c = plant.from_network_1(line_3);
    const auto r = read_memory(*c);
    EXPECT_EQ(r.code.raw(), 0x0000);
    EXPECT_EQ(r.header.source, line_3);
    // Sent with GCT 02: 01 when it reaches 3.5 (2 routers: 02 -> 01 -> 00), the answer
    // starts at that value and crosses the same two routers on its way back.
    EXPECT_EQ(r.header.gateway_count, 0);
    // SNA 00 became network 1 at the first router, so the answer is for network 1.
    EXPECT_EQ(r.header.destination.network, 1);
}

TEST(Plant, W342_5_1_3_UnknownNetworkAnswers0501FromTheFirstRouter) {
    PlantThread plant;
    auto c = plant.from_network_1({9, 5, 0});
    expect_relay_error(read_memory(*c), 0x0501, {1, 1});
}

TEST(Plant, W342_5_1_3_UnknownNetworkAtTheSecondRouterNamesIt) {
    auto config = three_networks();
    config.cpus[0].relays.push_back({4, 2, 2});  // router-a sends network 4 to router-b
    PlantThread plant(config);
    auto c = plant.from_network_1({4, 5, 0});
    expect_relay_error(read_memory(*c), 0x0501, {2, 2});
}

TEST(Plant, W342_5_1_3_GatewayCountExhaustedAnswers0504) {
    PlantThread plant;
    ClientOptions o;
    o.gateway_count = 1;  // router-a makes it 00, router-b cannot cross another network
    auto c = plant.client("127.0.1.1", plant.port(0), line_3, false, o);
    expect_relay_error(read_memory(*c), 0x0504, {2, 2});
}

TEST(Plant, W342_5_1_3_NoRoutingTablesAnswers0502AfterParameterAreaClear) {
    PlantThread plant;
    auto admin = plant.client("127.0.1.1", plant.port(0), {1, 1, 0});
    // 02 03 PARAMETER AREA CLEAR of the whole 8013 area (W342 5-3-9).
    const auto cleared =
        admin->send_raw({0x02, 0x03}, be16s({plc::routing_table_area, 0x0000, 0x0200, 0x0000}));
    ASSERT_TRUE(cleared);
    ASSERT_EQ(cleared->code.raw(), 0x0000);
    auto c = plant.from_network_1(line_3);
    expect_relay_error(read_memory(*c), 0x0502, {1, 1});
    // Its own memory still answers: only relaying needs the tables.
    EXPECT_EQ(read_memory(*admin).code.raw(), 0x0000);
}

TEST(Plant, W342_5_1_3_BrokenRoutingTablesAnswer0503) {
    PlantThread plant;
    auto admin = plant.client("127.0.1.1", plant.port(0), {1, 1, 0});
    auto c = plant.from_network_1(line_3);
    // Local network table entry 2: network 2 on unit 0F, which is not mounted.
    EXPECT_EQ(write_routing_words(*admin, 0x0002, {0x020F}).code.raw(), 0x0000);
    expect_relay_error(read_memory(*c), 0x0503, {1, 1});
    // A relay network that is not a local network: the tables are broken as a whole.
    EXPECT_EQ(write_routing_words(*admin, 0x0002, {0x0201}).code.raw(), 0x0000);
    EXPECT_EQ(read_memory(*c).code.raw(), 0x0000);
    EXPECT_EQ(write_routing_words(*admin, 0x0011, {0x0309}).code.raw(), 0x0000);
    expect_relay_error(read_memory(*c), 0x0503, {1, 1});
}

TEST(Plant, W342_5_3_8_ParameterAreaWriteChangesRoutingAtRunTime) {
    PlantThread plant;
    auto admin = plant.client("127.0.1.1", plant.port(0), {1, 1, 0});
    auto c = plant.from_network_1(line_3);
    ASSERT_EQ(read_memory(*c).code.raw(), 0x0000);
    // 02 01 reads the tables the configuration wrote (routing_tables.hpp layout).
    const auto read = admin->send_raw({0x02, 0x01}, be16s({plc::routing_table_area, 0, 0x13}));
    ASSERT_TRUE(read);
    ASSERT_EQ(read->code.raw(), 0x0000);
    const std::vector<std::uint8_t> expected = be16s({plc::routing_table_area,
                                                      0x0000,
                                                      0x0013,
                                                      0x0002,
                                                      0x0100,
                                                      0x0201,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0,
                                                      0x0302,
                                                      0x0002});
    EXPECT_EQ(read->data, expected);
    // The relay entry for network 3 now names network 4: network 3 is unknown.
    EXPECT_EQ(write_routing_words(*admin, 0x0011, {0x0402}).code.raw(), 0x0000);
    expect_relay_error(read_memory(*c), 0x0501, {1, 1});
    EXPECT_EQ(write_routing_words(*admin, 0x0011, {0x0302}).code.raw(), 0x0000);
    EXPECT_EQ(read_memory(*c).code.raw(), 0x0000);
}

TEST(Plant, W596_2_3_RelayNodeWithoutAnAddressAnswers0201) {
    auto config = three_networks();
    // Network 2 by the IP address table with no entry: node 9 has no address.
    config.cpus[0].ports[1].method = server::AddressMethod::table;
    config.cpus[0].relays.push_back({5, 2, 9});
    PlantThread plant(config);
    auto c = plant.from_network_1({5, 1, 0});
    expect_relay_error(read_memory(*c), 0x0201, {1, 1});
    // Relay nodes of this process are reached whatever the table says.
    EXPECT_EQ(read_memory(*plant.from_network_1(line_3)).code.raw(), 0x0000);
}

TEST(Plant, W596_A_1_DestinationNetwork0IsTheArrivalNetwork) {
    PlantThread plant;
    // DNA 00 to router-a's network-1 unit: router-a itself answers.
    auto c = plant.client("127.0.1.1", plant.port(0), {0, 1, 0});
    const auto r = read_memory(*c);
    EXPECT_EQ(r.code.raw(), 0x0000);
    EXPECT_EQ(r.header.source, (NodeAddress{1, 1, 0}));
    // Router-a's other unit, addressed from network 1, is router-a as well.
    auto other = plant.client("127.0.1.1", plant.port(0), {2, 1, 0});
    const auto r2 = read_memory(*other);
    EXPECT_EQ(r2.code.raw(), 0x0000);
    EXPECT_EQ(r2.header.source, (NodeAddress{2, 1, 0}));
}

TEST(Plant, W596_2_4_BetweenTwoProcessesTheRelayIsFinsUdp) {
    // The routers in one plant, line-3 in another (another finsd): router-b reaches
    // 127.0.3.5 by its node-address table (automatic: 127.0.3.5 at its own port), and
    // the answer comes back as datagrams routed by DNA through both routers to the
    // client's learned address. All units share one port, as on a real network.
    constexpr std::uint16_t port = 29661;
    const auto [routers, line] = routers_and_line(port);
    PlantThread a(routers);
    PlantThread b(line);
    // FINS/UDP from node 77 of network 1 (no router uses it); FINS/TCP from the node the
    // handshake gives, the answer coming back on that connection.
    for (const bool tcp : {false, true}) {
        ClientOptions o;
        o.source = {0, 77, 0};
        auto c = a.client("127.0.1.1", port, line_3, tcp, o);
        const std::array<std::uint16_t, 2> words{0xCAFE, static_cast<std::uint16_t>(tcp)};
        ASSERT_TRUE(c->write_words(dm(300), words));
        const auto got = c->read_words(dm(300), 2);
        ASSERT_TRUE(got) << got.error().message();
        EXPECT_EQ(*got, std::vector<std::uint16_t>(words.begin(), words.end()));
        auto direct = b.client("127.0.3.5", port, line_3);
        EXPECT_EQ(*direct->read_words(dm(300), 2), *got);
    }
}

TEST(Plant, W342_5_1_3_ARelayLoopEndsWith0504EvenFromAGctAbove07) {
    auto config = three_networks();
    config.cpus[0].relays.push_back({9, 2, 2});  // router-a: network 9 via router-b
    config.cpus[1].relays.push_back({9, 2, 1});  // router-b: network 9 via router-a
    PlantThread plant(config);
    ClientOptions o;
    o.gateway_count = 0xFF;  // taken as 07: at most 7 more crossings
    auto c = plant.client("127.0.1.1", plant.port(0), {9, 5, 0}, false, o);
    const auto r = read_memory(*c);
    EXPECT_EQ(r.code.raw(), 0x8504);
    ASSERT_TRUE(r.relay);
    // 07 -> 06 (a), 05 (b), 04 (a), 03 (b), 02 (a), 01 (b), 00 (a); b finds 00.
    EXPECT_EQ(*r.relay, (RelayErrorSource{2, 2}));
}

// fins-frames.md 1.3: DA1 FF is a broadcast, sent without an answer (W343 08 03). To
// another network it is relayed as a broadcast there (README "Routing"): line-3 on
// network 3 runs it; no answer comes back through the routers. Before: 8201 from
// router-b, which looked for a node FF.
TEST(Plant, Frames_1_3_BroadcastToAnotherNetworkRunsThereAndIsNotAnswered) {
    PlantThread plant;
    ClientOptions o;
    o.timeout = std::chrono::milliseconds(300);
    auto c = plant.client("127.0.1.1", plant.port(0), {3, broadcast_node, 0}, false, o);
    auto direct = plant.client("127.0.3.5", plant.port(2), line_3);
    ASSERT_TRUE(c && direct);
    // 01 02 D200 = 1234, no answer asked.
    ASSERT_TRUE(c->send_no_response(
        {0x01, 0x02}, std::vector<std::uint8_t>{0x82, 0x00, 0xC8, 0x00, 0x00, 0x01, 0x12, 0x34}));
    std::uint16_t seen = 0;
    for (int i = 0; i < 100 && seen != 0x1234; ++i) {
        const auto r = direct->read_words(dm(200), 1);
        if (r && !r->empty()) seen = r->front();
    }
    EXPECT_EQ(seen, 0x1234);
    // An answer asked for: the command runs there, and none comes back.
    const auto r = c->send_raw(
        {0x01, 0x02}, std::vector<std::uint8_t>{0x82, 0x00, 0xC9, 0x00, 0x00, 0x01, 0x56, 0x78});
    EXPECT_FALSE(r.has_value()) << "answered " << std::hex << r->code.raw();
    const auto after = direct->read_words(dm(201), 1);
    ASSERT_TRUE(after);
    EXPECT_EQ(*after, std::vector<std::uint16_t>{0x5678});
}

}  // namespace
}  // namespace fins::test
