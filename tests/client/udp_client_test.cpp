// fins::Client over FINS/UDP against the in-test responder on 127.0.0.1 / ::1, port 0.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "client/loopback_servers.hpp"
#include "fins/client.hpp"

using namespace fins;
using namespace fins::test;
using namespace std::chrono_literals;

namespace {

std::unique_ptr<Client> connect_udp(const UdpResponder& server, ClientOptions options = {}) {
    options.port = server.port();
    options.protocol = ClientOptions::Protocol::udp;
    auto client = Client::connect(options);
    EXPECT_TRUE(client) << (client ? "" : client.error().message());
    return client ? std::move(*client) : nullptr;
}

Address dm(std::uint16_t word) {
    return Address{Area::dm, 0, word, std::nullopt};
}

TEST(UdpClient, DerivesNodesOnLoopback) {
    UdpResponder server;
    auto client = connect_udp(server);
    ASSERT_TRUE(client);
    EXPECT_EQ(client->destination(), (NodeAddress{0, 1, 0}));
    EXPECT_EQ(client->source(), (NodeAddress{0, 254, 0})) << "127.0.0.1 on both ends: 254";
    EXPECT_TRUE(client->is_connected());
}

TEST(UdpClient, ConfiguredNodesAreUsedAsGiven) {
    UdpResponder server;
    ClientOptions options;
    options.destination = NodeAddress{0, 1, 0};
    options.source = NodeAddress{0, 7, 0};
    auto client = connect_udp(server, options);
    ASSERT_TRUE(client);
    ASSERT_TRUE(client->read_words(dm(0), 1));
    auto frames = server.requests();
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0][4], 1);
    EXPECT_EQ(frames[0][7], 7);
}

// W342 (DA1 00: "internal communications inside the local PLC"): a destination node 0
// given as is goes out as node 0, not the node derived from the host's IP.
TEST(UdpClient, W342DestinationNode00IsSentAsWrittenWhenGivenAsIs) {
    UdpResponder server;
    ClientOptions options;
    options.destination = NodeAddress{0, 0, 0};
    options.destination_as_given = true;
    options.timeout = 200ms;
    auto client = connect_udp(server, options);
    ASSERT_TRUE(client);
    EXPECT_EQ(client->destination(), (NodeAddress{0, 0, 0}));
    (void)client->read_words(dm(0), 1);  // answered or not: what was sent is the point
    auto frames = server.requests();
    ASSERT_GE(frames.size(), 1u);
    EXPECT_EQ(frames[0][4], 0) << "DA1 as written";
    EXPECT_EQ(frames[0][7], 1) << "the source is still derived (127.0.0.1, not node 0)";
}

// Without destination_as_given, node 0 still means "derive" (existing users).
TEST(UdpClient, DestinationNode0WithoutAsGivenIsDerived) {
    UdpResponder server;
    ClientOptions options;
    options.destination = NodeAddress{0, 0, 0};
    auto client = connect_udp(server, options);
    ASSERT_TRUE(client);
    EXPECT_EQ(client->destination(), (NodeAddress{0, 1, 0}));
}

TEST(UdpClient, TypedSendReadsAndWrites) {
    UdpResponder server;
    auto client = connect_udp(server);
    ASSERT_TRUE(client);
    std::array<std::uint8_t, 4> data{0x12, 0x34, 0xAB, 0xCD};
    auto written = client->send(MemoryAreaWrite{{0x82, 100, 0}, 2, data});
    ASSERT_TRUE(written) << written.error().message();
    auto read = client->send(MemoryAreaRead{{0x82, 100, 0}, 2});
    ASSERT_TRUE(read);
    EXPECT_EQ(read->data, (std::vector<std::uint8_t>{0x12, 0x34, 0xAB, 0xCD}));
    EXPECT_EQ(client->stats().sent, 2u);
    EXPECT_EQ(client->stats().completed, 2u);
}

TEST(UdpClient, WorksOverIpv6Loopback) {
    UdpResponder server("::1");
    if (!server.ok()) GTEST_SKIP() << "no IPv6 loopback";
    ClientOptions options;
    options.host = "::1";
    auto client = connect_udp(server, options);
    ASSERT_TRUE(client);
    EXPECT_EQ(client->destination().node, 1);
    server.with_plc([](FakePlc& plc) { plc.dm[5] = 0xBEEF; });
    auto words = client->read_words(dm(5), 1);
    ASSERT_TRUE(words);
    EXPECT_EQ((*words)[0], 0xBEEF);
}

TEST(UdpClient, ThirtyTwoAsyncRequestsAnsweredInReverseOrder) {
    UdpResponder server;
    server.hold_until(32);  // answers only once all 32 are in flight together
    server.with_plc([](FakePlc& plc) {
        for (std::uint16_t i = 0; i < 32; ++i)
            plc.dm[i] = static_cast<std::uint16_t>(1000 + i);
    });
    auto client = connect_udp(server);
    ASSERT_TRUE(client);
    std::vector<std::optional<std::uint16_t>> got(32);
    for (std::uint16_t i = 0; i < 32; ++i) {
        client->async_send(MemoryAreaRead{{0x82, i, 0}, 1},
                           [&got, i](Result<MemoryAreaReadResponse> r) {
                               ASSERT_TRUE(r) << r.error().message();
                               got[i] = static_cast<std::uint16_t>((r->data[0] << 8) | r->data[1]);
                           });
    }
    EXPECT_EQ(client->in_flight(), 32u);
    client->run();
    for (std::uint16_t i = 0; i < 32; ++i)
        EXPECT_EQ(got[i], 1000 + i);
    EXPECT_EQ(client->in_flight(), 0u);
}

TEST(UdpClient, RetransmitsTheSameFrameThenTimesOut) {
    UdpResponder server;
    server.set_silent(true);
    ClientOptions options;
    options.timeout = 30ms;
    options.retries = 2;
    auto client = connect_udp(server, options);
    ASSERT_TRUE(client);
    auto r = client->read_words(dm(0), 1);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), make_error_code(ClientError::timeout));
    ASSERT_TRUE(server.wait_for_requests(3));
    auto frames = server.requests();
    ASSERT_EQ(frames.size(), 3u);
    EXPECT_EQ(frames[1], frames[0]);
    EXPECT_EQ(frames[2], frames[0]);
    EXPECT_EQ(client->stats().retransmitted, 2u);
    EXPECT_EQ(client->stats().timed_out, 1u);
}

TEST(UdpClient, RefusesMoreThan15Retries) {
    ClientOptions options;
    options.retries = 16;
    auto client = Client::connect(options);
    ASSERT_FALSE(client);
    EXPECT_EQ(client.error(), make_error_code(ClientError::invalid_argument));
}

TEST(UdpClient, NoResponseModeSendsIcf81AndWaitsForNothing) {
    UdpResponder server;
    auto client = connect_udp(server);
    ASSERT_TRUE(client);
    std::array<std::uint8_t, 2> data{0x00, 0x2A};
    ASSERT_TRUE(client->send_no_response(MemoryAreaWrite{{0x82, 9, 0}, 1, data}));
    EXPECT_EQ(client->in_flight(), 0u);
    ASSERT_TRUE(server.wait_for_requests(1));
    EXPECT_EQ(server.requests()[0][0], 0x81);
    // The write still happened; a normal request after it proves the order.
    auto words = client->read_words(dm(9), 1);
    ASSERT_TRUE(words);
    EXPECT_EQ((*words)[0], 0x2A);
}

TEST(UdpClient, EndCodeBecomesAnErrorButFlagBitsAloneAreSuccess) {
    UdpResponder server;
    auto client = connect_udp(server);
    ASSERT_TRUE(client);
    server.with_plc([](FakePlc& plc) { plc.fail_word = 40; });
    auto failed = client->read_words(dm(40), 1);
    ASSERT_FALSE(failed);
    EXPECT_EQ(failed.error(), make_error_code(EndCode::address_range_error));
    server.with_plc([](FakePlc& plc) {
        plc.fail_word.reset();
        plc.end_code_flags = 0x0040;  // non-fatal CPU error (battery): still success
    });
    EXPECT_TRUE(client->read_words(dm(40), 1));
    server.with_plc([](FakePlc& plc) { plc.end_code_flags = 0x0080; });
    EXPECT_TRUE(client->read_words(dm(40), 1));
}

TEST(UdpClient, SendRawLeavesTheEndCodeToTheCaller) {
    UdpResponder server;
    auto client = connect_udp(server);
    ASSERT_TRUE(client);
    auto r = client->send_raw(CommandCode{0x07, 0x01}, {});
    ASSERT_TRUE(r) << r.error().message();
    EXPECT_EQ(r->code.raw(), 0x0401);
    EXPECT_EQ(r->command, (CommandCode{0x07, 0x01}));
    EXPECT_EQ(r->header.source.node, 1);
    EXPECT_FALSE(r->relay);
    const std::array<std::uint8_t, 6> read_d10{0x82, 0x00, 0x0A, 0x00, 0x00, 0x02};
    server.with_plc([](FakePlc& plc) {
        plc.dm[10] = 0x0102;
        plc.dm[11] = 0x0304;
    });
    auto raw = client->send_raw(CommandCode{0x01, 0x01}, read_d10);
    ASSERT_TRUE(raw);
    EXPECT_TRUE(raw->code.ok());
    EXPECT_EQ(raw->data, (std::vector<std::uint8_t>{1, 2, 3, 4}));
}

TEST(UdpClient, AsyncSendRawCompletesFromRun) {
    UdpResponder server;
    auto client = connect_udp(server);
    ASSERT_TRUE(client);
    int done = 0;
    for (int i = 0; i < 5; ++i)
        client->async_send_raw(CommandCode{0x07, 0x01}, {}, [&done](Result<RawResponse> r) {
            EXPECT_TRUE(r);
            ++done;
        });
    client->run();
    EXPECT_EQ(done, 5);
}

TEST(UdpClient, DuplicateAnswersAreDiscardedAndCounted) {
    UdpResponder server;
    server.set_duplicate(true);
    auto client = connect_udp(server);
    ASSERT_TRUE(client);
    ASSERT_TRUE(client->read_words(dm(0), 1));
    ASSERT_TRUE(client->read_words(dm(1), 1));  // the first duplicate arrives before this answer
    EXPECT_GE(client->stats().stale_discarded, 1u);
    EXPECT_EQ(client->stats().completed, 2u);
}

TEST(UdpClient, OversizedCommandFailsWithoutSending) {
    UdpResponder server;
    auto client = connect_udp(server);
    ASSERT_TRUE(client);
    std::vector<std::uint8_t> data(2 * 1100);
    auto r = client->send(MemoryAreaWrite{{0x82, 0, 0}, 1100, data});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), make_error_code(ClientError::request_too_long));
    EXPECT_EQ(client->stats().sent, 0u);
}

}  // namespace
