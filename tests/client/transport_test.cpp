// Transport details seen through the client: node derivation from IP addresses, the
// bound on a FINS/TCP handshake that never completes, ICMP port-unreachable on UDP.
#include <gtest/gtest.h>

#include <asio/ip/address.hpp>
#include <asio/ip/udp.hpp>

#include "client/loopback_servers.hpp"
#include "fins/client.hpp"
#include "transport/transport.hpp"

using namespace fins;
using namespace fins::test;
using namespace std::chrono_literals;

namespace {

std::uint8_t node_of(const char* text) {
    return transport::node_from_address(asio::ip::make_address(text));
}

TEST(NodeFromAddress, LastOctetAndLoopback) {
    EXPECT_EQ(node_of("192.168.250.10"), 10);
    EXPECT_EQ(node_of("10.0.0.254"), 254);
    EXPECT_EQ(node_of("127.0.0.1"), 1);
    EXPECT_EQ(node_of("127.0.0.9"), 1) << "any loopback address is node 1";
    EXPECT_EQ(node_of("::1"), 1);
    EXPECT_EQ(node_of("::ffff:192.168.0.7"), 7);
    EXPECT_EQ(node_of("::ffff:127.0.0.1"), 1);
    EXPECT_EQ(node_of("fe80::1:12"), 0x12);
}

TEST(TcpTransport, HandshakeThatNeverCompletesTimesOut) {
    TcpBehaviour behaviour;
    behaviour.mode = TcpBehaviour::Mode::mute;
    TcpResponder server(behaviour);
    ClientOptions options;
    options.protocol = ClientOptions::Protocol::tcp;
    options.port = server.port();
    options.timeout = 50ms;
    const auto start = std::chrono::steady_clock::now();
    auto client = Client::connect(options);
    ASSERT_FALSE(client);
    EXPECT_EQ(client.error(), make_error_code(ClientError::timeout));
    EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
}

TEST(UdpTransport, PortUnreachableIsATimeoutNotAClosedConnection) {
    std::uint16_t port = 0;
    {
        asio::io_context io;
        asio::ip::udp::socket probe(io, {asio::ip::make_address("127.0.0.1"), 0});
        port = probe.local_endpoint().port();
    }  // closed again: the kernel answers ICMP port unreachable
    ClientOptions options;
    options.port = port;
    options.timeout = 30ms;
    options.retries = 1;
    auto client = Client::connect(options);
    ASSERT_TRUE(client);
    auto r = (*client)->read_words(Address{Area::dm, 0, 0, std::nullopt}, 1);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), make_error_code(ClientError::timeout));
    EXPECT_TRUE((*client)->is_connected());
    EXPECT_EQ((*client)->stats().retransmitted, 1u);
}

}  // namespace
