// fins::Client over FINS/TCP against the in-test server: handshake, framing of answers
// split at every byte position and glued together, connection loss and reconnect,
// handshake and envelope errors.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include <boost/asio/ip/tcp.hpp>

#include "client/loopback_servers.hpp"
#include "fins/client.hpp"
#include "transport/asio.hpp"

using namespace fins;
using namespace fins::test;
using namespace std::chrono_literals;

namespace {

ClientOptions tcp_options(const TcpResponder& server) {
    ClientOptions options;
    options.protocol = ClientOptions::Protocol::tcp;
    options.port = server.port();
    return options;
}

std::unique_ptr<Client> connect_with(const ClientOptions& options) {
    auto client = Client::connect(options);
    EXPECT_TRUE(client) << (client ? "" : client.error().message());
    return client ? std::move(*client) : nullptr;
}

std::unique_ptr<Client> connect_tcp(const TcpResponder& server) {
    return connect_with(tcp_options(server));
}

Address dm(std::uint16_t word) {
    return Address{Area::dm, 0, word, std::nullopt};
}

TEST(TcpClient, HandshakeAllocatesTheClientNodeAndLearnsTheServerNode) {
    TcpResponder server;
    auto client = connect_tcp(server);
    ASSERT_TRUE(client);
    EXPECT_EQ(server.handshakes(), (std::vector<std::uint8_t>{0}));
    EXPECT_EQ(client->source().node, 0x22);
    EXPECT_EQ(client->destination().node, 10);
    ASSERT_TRUE(client->read_words(dm(0), 1));
    auto frames = server.requests();
    ASSERT_EQ(frames.size(), 1u);
    EXPECT_EQ(frames[0][4], 10) << "DA1 = server node";
    EXPECT_EQ(frames[0][7], 0x22) << "SA1 = allocated client node";
}

TEST(TcpClient, AConfiguredSourceNodeIsRequestedInTheHandshake) {
    TcpResponder server;
    auto options = tcp_options(server);
    options.source.node = 5;
    auto client = connect_with(options);
    ASSERT_TRUE(client);
    EXPECT_EQ(server.handshakes(), (std::vector<std::uint8_t>{5}));
    EXPECT_EQ(client->source().node, 5);
}

// W342: a destination node 0 given as is is sent as node 0, not the handshake's node.
TEST(TcpClient, W342DestinationNode00IsSentAsWrittenWhenGivenAsIs) {
    TcpResponder server;
    auto options = tcp_options(server);
    options.destination = NodeAddress{0, 0, 0};
    options.destination_as_given = true;
    options.timeout = std::chrono::milliseconds(200);
    auto client = connect_with(options);
    ASSERT_TRUE(client);
    EXPECT_EQ(client->destination(), (NodeAddress{0, 0, 0}));
    (void)client->read_words(dm(0), 1);
    auto frames = server.requests();
    ASSERT_GE(frames.size(), 1u);
    EXPECT_EQ(frames[0][4], 0) << "DA1 as written, not the server node 10";
}

TEST(TcpClient, WorksOverIpv6Loopback) {
    TcpResponder server({}, "::1");
    if (!server.ok()) GTEST_SKIP() << "no IPv6 loopback";
    auto options = tcp_options(server);
    options.host = "::1";
    auto client = connect_with(options);
    ASSERT_TRUE(client);
    server.with_plc([](FakePlc& plc) { plc.dm[3] = 0x1234; });
    auto words = client->read_words(dm(3), 1);
    ASSERT_TRUE(words);
    EXPECT_EQ((*words)[0], 0x1234);
}

// The server writes each answer in two parts; loopback often hands both to one read,
// so this pins only that the client copes with the writes. That the client's reader
// really sees every split position is pinned by
// TcpTransport.SeesAPacketSplitAtEveryBytePosition (transport_test.cpp).
TEST(TcpClient, AnswersWrittenSplitAtEveryBytePosition) {
    TcpBehaviour behaviour;
    behaviour.mode = TcpBehaviour::Mode::split;
    TcpResponder server(behaviour);
    auto client = connect_tcp(server);
    ASSERT_TRUE(client);
    server.with_plc([](FakePlc& plc) {
        for (std::uint16_t i = 0; i < 64; ++i)
            plc.dm[i] = static_cast<std::uint16_t>(0x0100 + i);
    });
    // A one-word read answer is 16 + 14 + 2 = 32 bytes: split positions 1 .. 31.
    constexpr std::uint16_t packet = 32;
    for (std::uint16_t i = 0; i < packet - 1; ++i) {
        auto words = client->read_words(dm(i), 1);
        ASSERT_TRUE(words) << "split at " << i + 1 << ": " << words.error().message();
        EXPECT_EQ((*words)[0], 0x0100 + i);
    }
    EXPECT_EQ(server.split_answers(), packet - 1u) << "what the server wrote, not what was read";
}

TEST(TcpClient, TwoAnswersGluedInOneWrite) {
    TcpBehaviour behaviour;
    behaviour.mode = TcpBehaviour::Mode::glue;
    TcpResponder server(behaviour);
    auto client = connect_tcp(server);
    ASSERT_TRUE(client);
    server.with_plc([](FakePlc& plc) {
        for (std::uint16_t i = 0; i < 10; ++i)
            plc.dm[i] = static_cast<std::uint16_t>(7 * i);
    });
    std::vector<std::optional<std::uint16_t>> got(10);
    for (std::uint16_t i = 0; i < 10; ++i)
        client->async_send(MemoryAreaRead{{0x82, i, 0}, 1},
                           [&got, i](Result<MemoryAreaReadResponse> r) {
                               ASSERT_TRUE(r) << r.error().message();
                               got[i] = static_cast<std::uint16_t>((r->data[0] << 8) | r->data[1]);
                           });
    client->run();
    for (std::uint16_t i = 0; i < 10; ++i)
        EXPECT_EQ(got[i], 7 * i);
}

TEST(TcpClient, DropFailsEverythingInFlightThenTheNextRequestReconnects) {
    TcpBehaviour behaviour;
    behaviour.mode = TcpBehaviour::Mode::drop_first;
    TcpResponder server(behaviour);
    auto client = connect_tcp(server);
    ASSERT_TRUE(client);
    std::vector<std::error_code> errors;
    for (std::uint16_t i = 0; i < 3; ++i)
        client->async_send(MemoryAreaRead{{0x82, i, 0}, 1},
                           [&errors](Result<MemoryAreaReadResponse> r) {
                               errors.push_back(r ? std::error_code{} : r.error());
                           });
    client->run();
    ASSERT_EQ(errors.size(), 3u);
    for (const auto& ec : errors)
        EXPECT_EQ(ec, make_error_code(ClientError::connection_closed));
    EXPECT_FALSE(client->is_connected());
    EXPECT_EQ(client->stats().failed, 3u);

    server.with_plc([](FakePlc& plc) { plc.dm[1] = 99; });
    auto words = client->read_words(dm(1), 1);
    ASSERT_TRUE(words) << words.error().message();
    EXPECT_EQ((*words)[0], 99);
    EXPECT_EQ(server.handshakes().size(), 2u);
    EXPECT_EQ(client->stats().reconnects, 1u);
    EXPECT_TRUE(client->is_connected());
}

// finsd restarted while the client was idle: its end of stream waits unread on the old
// socket. The first request goes out on a new connection (header: "the next request
// reconnects") instead of failing with connection_closed.
TEST(TcpClient, FirstRequestAfterTheServerClosedAnIdleConnectionSucceeds) {
    TcpResponder server;
    auto client = connect_tcp(server);
    ASSERT_TRUE(client);
    server.with_plc([](FakePlc& plc) { plc.dm[7] = 0x0707; });
    ASSERT_TRUE(client->read_words(dm(7), 1));
    ASSERT_TRUE(server.drop_connections());
    for (int round = 0; round < 3; ++round) {
        auto words = client->read_words(dm(7), 1);
        ASSERT_TRUE(words) << "round " << round << ": " << client->describe(words.error());
        EXPECT_EQ((*words)[0], 0x0707);
        ASSERT_TRUE(server.drop_connections());
    }
    EXPECT_EQ(server.handshakes().size(), 4u);
    EXPECT_EQ(client->stats().failed, 0u);
    EXPECT_EQ(client->stats().reconnects, 3u);
}

TEST(TcpClient, HandshakeErrorFailsConnectWithTheTcpError) {
    TcpBehaviour behaviour;
    behaviour.mode = TcpBehaviour::Mode::handshake_error;
    behaviour.error = 0x21;
    TcpResponder server(behaviour);
    auto client = Client::connect(tcp_options(server));
    ASSERT_FALSE(client);
    EXPECT_EQ(client.error(), make_error_code(TcpError::node_already_connected));
}

TEST(TcpClient, FrameErrorNotificationFailsInFlightWithItsCode) {
    TcpBehaviour behaviour;
    behaviour.mode = TcpBehaviour::Mode::frame_error;
    TcpResponder server(behaviour);
    auto client = connect_tcp(server);
    ASSERT_TRUE(client);
    auto r = client->read_words(dm(0), 1);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), make_error_code(TcpError::command_not_supported));
    EXPECT_TRUE(client->read_words(dm(0), 1)) << "reconnects after the error";
}

TEST(TcpClient, ConnectionConfirmationPacketsAreIgnored) {
    TcpBehaviour behaviour;
    behaviour.mode = TcpBehaviour::Mode::confirm;
    TcpResponder server(behaviour);
    auto client = connect_tcp(server);
    ASSERT_TRUE(client);
    for (std::uint16_t i = 0; i < 3; ++i)
        EXPECT_TRUE(client->read_words(dm(i), 1));
    EXPECT_TRUE(client->is_connected());
}

TEST(TcpClient, UnknownEnvelopeCommandIsAnsweredWithCommand3AndCloses) {
    TcpBehaviour behaviour;
    behaviour.mode = TcpBehaviour::Mode::unknown_command;
    TcpResponder server(behaviour);
    auto client = connect_tcp(server);
    ASSERT_TRUE(client);
    auto r = client->read_words(dm(0), 1);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), make_error_code(TcpError::command_not_supported));
    // The notification reached the server before the client closed (frames 3.4 item 4).
    EXPECT_EQ(server.envelope_errors(1), (std::vector<std::uint32_t>{0x03}));
}

TEST(TcpClient, ConnectionRefusedIsReported) {
    std::uint16_t port = 0;
    {
        asio::io_context io;
        asio::ip::tcp::acceptor probe(io, {asio::ip::make_address("127.0.0.1"), 0});
        port = probe.local_endpoint().port();
    }  // closed again: nothing listens there now
    ClientOptions options;
    options.protocol = ClientOptions::Protocol::tcp;
    options.port = port;
    auto client = Client::connect(options);
    ASSERT_FALSE(client);
    EXPECT_EQ(client.error(), make_error_code(asio::error::connection_refused));
    EXPECT_EQ(describe_error(options, client.error()),
              "127.0.0.1:" + std::to_string(port) + ": connection refused");
}

TEST(TcpClient, CloseCancelsAndTheNextRequestReconnects) {
    TcpResponder server;
    auto client = connect_tcp(server);
    ASSERT_TRUE(client);
    std::optional<std::error_code> error;
    client->async_send(MemoryAreaRead{{0x82, 0, 0}, 1}, [&error](Result<MemoryAreaReadResponse> r) {
        error = r ? std::error_code{} : r.error();
    });
    client->close();
    ASSERT_TRUE(error);
    EXPECT_EQ(*error, make_error_code(ClientError::canceled));
    EXPECT_TRUE(client->read_words(dm(0), 1));
    EXPECT_EQ(server.handshakes().size(), 2u);
}

TEST(TcpClient, LongReadIsSplitIntoThreeRequests) {
    TcpResponder server;
    auto client = connect_tcp(server);
    ASSERT_TRUE(client);
    server.with_plc([](FakePlc& plc) {
        for (std::uint16_t i = 0; i < 2000; ++i)
            plc.dm[i] = static_cast<std::uint16_t>(i ^ 0x5A5A);
    });
    auto words = client->read_words(dm(0), 2000);
    ASSERT_TRUE(words) << words.error().message();
    ASSERT_EQ(words->size(), 2000u);
    for (std::uint16_t i = 0; i < 2000; ++i)
        ASSERT_EQ((*words)[i], i ^ 0x5A5A) << i;
    EXPECT_EQ(server.requests().size(), 3u);
}

}  // namespace
