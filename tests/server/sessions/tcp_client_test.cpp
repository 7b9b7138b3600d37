// finsd's FINS/TCP client connections (tcp_client.hpp): node A opens a connection to
// node B ([[remote]] transport = "tcp") and runs Send/Rcv/SendCmd over it; both nodes
// run in this process on one I/O thread, loopback only.
#include "server/sessions/tcp_client.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <memory>
#include <thread>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "plc/plc.hpp"
#include "server/sessions/io_thread.hpp"
#include "server/sessions/server.hpp"
#include "server/sessions/tcp_peer.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using server::InstructionKind;
using server::InstructionRequest;
using server::InstructionResult;

// Nodes on one I/O thread; every call into them is posted there.
struct Nodes : IoThread {
    Harness a_plc;
    Harness b_plc;
    std::unique_ptr<server::Server> a;
    std::unique_ptr<server::Server> b;

    ~Nodes() { stop(); }
    // B: node 5, FINS/TCP only. A: node 1, FINS/UDP off, a client connection to
    // `remote_node` at B's port, allowed `max_connections` FINS/TCP connections.
    void start(std::uint8_t remote_node = 5, std::size_t max_connections = 16) {
        server::ServerOptions ob;
        ob.port = 0;
        ob.udp = false;
        ob.node = 5;
        auto b_started = server::Server::start(io, b_plc.plc, ob);
        ASSERT_TRUE(b_started.has_value());
        b = std::move(*b_started);
        server::ServerOptions oa;
        oa.port = 0;
        oa.udp = false;
        oa.node = 1;
        oa.max_tcp_connections = max_connections;
        oa.remotes = {server::RemoteNode{0, remote_node, "127.0.0.1", b->tcp_port(), true, 0}};
        oa.tcp_client_timing.retry_min = std::chrono::milliseconds(10);
        oa.tcp_client_timing.retry_max = std::chrono::milliseconds(50);
        auto a_started = server::Server::start(io, a_plc.plc, oa);
        ASSERT_TRUE(a_started.has_value());
        a = std::move(*a_started);
        start_thread();
    }
    // Bounded wait until A's client connection is up (or is not, `up` false).
    bool wait_client(bool up) {
        return wait([this, up] { return a->tcp_clients()[0]->established() == up; });
    }
    // Runs `request` on A (on B with `on_b`).
    InstructionResult run(InstructionRequest request, bool on_b = false) {
        return IoThread::run(on_b ? *b : *a, std::move(request));
    }
};

InstructionRequest send_to_5() {
    InstructionRequest r;
    r.kind = InstructionKind::send;
    r.destination = {0, 5, 0};
    r.local = *parse_address("D100");
    r.remote = *parse_address("D200");
    r.count = 2;
    r.options.timeout = 20;
    return r;
}

// W596 3: Send over the client connection writes B's words; the frame carries the client
// node B gave A as SA1 (W421 7-4), else B would drop it.
TEST(TcpClient, W596_3_SendAndRcvGoOverTheClientConnection) {
    Nodes n;
    n.start();
    ASSERT_NE(n.a, nullptr);
    ASSERT_EQ(n.on_io([&] { return n.a_plc.send("0102 82006400 0002 1111 2222").end_code(); }),
              0x0000);
    ASSERT_EQ(n.on_io([&] { return n.b_plc.send("0102 82006E00 0001 ABCD").end_code(); }),
              0x0000);  // D110
    ASSERT_TRUE(n.wait_client(true));
    const auto sent = n.run(send_to_5());
    EXPECT_TRUE(sent.done()) << sent.detail;
    EXPECT_EQ(n.on_io([&] { return n.b_plc.send("0101 8200C800 0002").data_hex(); }),
              "11 11 22 22");
    auto rcv = send_to_5();
    rcv.kind = InstructionKind::recv;
    rcv.remote = *parse_address("D110");
    rcv.local = *parse_address("D300");
    rcv.count = 1;
    const auto got = n.run(rcv);
    EXPECT_TRUE(got.done()) << got.detail;
    EXPECT_EQ(got.words, (std::vector<std::uint16_t>{0xABCD}));
    EXPECT_GE(n.on_io([&] { return n.a->tcp_clients()[0]->client_node(); }), 1);
}

// W421 7-4: FRAME SEND goes both ways. Node 5 reads node 1's words over the connection
// node 1 opened, addressing node 1 by the client node it gave it; node 1 answers as
// itself under that node number.
TEST(TcpClient, W421_7_4_TheServerReadsTheClientNodeOverTheSameConnection) {
    Nodes n;
    n.start();
    ASSERT_NE(n.a, nullptr);
    ASSERT_EQ(n.on_io([&] { return n.a_plc.send("0102 82006400 0001 BEEF").end_code(); }), 0x0000);
    ASSERT_TRUE(n.wait_client(true));
    const auto node = n.on_io([&] { return n.a->tcp_clients()[0]->client_node(); });
    auto rcv = send_to_5();
    rcv.kind = InstructionKind::recv;
    rcv.destination = {0, node, 0};
    rcv.remote = *parse_address("D100");
    rcv.local = *parse_address("D300");
    rcv.count = 1;
    const auto got = n.run(rcv, true);
    EXPECT_TRUE(got.done()) << got.detail;
    EXPECT_EQ(got.words, (std::vector<std::uint16_t>{0xBEEF}));
    EXPECT_EQ(n.on_io([&] { return n.a->tcp_clients()[0]->counters().served; }), 1u);
}

// W596 3 (Send error g, Rcv j, SendCmd h): with the connection down the instruction
// ends at once with 0800 / 0101 and nothing goes over FINS/UDP instead.
TEST(TcpClient, W596_3_ConnectionNotEstablishedIs0800With0101) {
    Nodes n;
    n.start();
    ASSERT_NE(n.a, nullptr);
    ASSERT_TRUE(n.wait_client(true));
    n.on_io([&] {
        n.b->stop();
        return 0;
    });
    ASSERT_TRUE(n.wait_client(false));
    const auto r = n.run(send_to_5());
    EXPECT_EQ(r.error_id, server::instruction_communications_error);
    EXPECT_EQ(r.error_id_ex, 0x0101);
    EXPECT_NE(r.detail.find("not established"), std::string::npos) << r.detail;
}

// The connection's identity: a server that says it is node 5 when [[remote]] names
// node 6 is not node 6; the connection never counts as established.
TEST(TcpClient, AServerOfAnotherNodeIsNotTheRemote) {
    Nodes n;
    n.start(6);
    ASSERT_NE(n.a, nullptr);
    for (int i = 0; i < 500; ++i) {
        if (n.on_io([&] { return n.a->tcp_clients()[0]->counters().failures; }) >= 2) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    EXPECT_GE(n.on_io([&] { return n.a->tcp_clients()[0]->counters().failures; }), 2u);
    EXPECT_FALSE(n.on_io([&] { return n.a->tcp_clients()[0]->established(); }));
    auto to6 = send_to_5();
    to6.destination.node = 6;
    EXPECT_EQ(n.run(to6).error_id_ex, 0x0101);
}

// W596 1-4 note 2: the limit is the "total number of server and client connections".
// With 2 allowed and one client connection configured, the second client that connects
// to A is refused in the handshake with 00000020 "All connections are in use" (W421 7-4).
TEST(TcpClient, W596_1_4_ClientConnectionsCountInTheLimit) {
    Nodes n;
    n.start(5, 2);
    ASSERT_NE(n.a, nullptr);
    TcpPeer first(n.a->tcp_port());
    ASSERT_TRUE(first.handshake());
    EXPECT_NE(first.node(), 0);
    TcpPeer second(n.a->tcp_port());
    std::array<std::uint8_t, 24> buf{};
    ByteWriter w{buf};
    write_node_address_request(w, 0);
    ASSERT_TRUE(second.send_all(buf.data(), w.size()));
    ASSERT_TRUE(second.receive(buf.data(), 24));
    EXPECT_EQ(buf[11], 0x01);  // command 1
    EXPECT_EQ(buf[15], 0x20);  // error: all connections are in use
}

// W421 7-4: a client unit "keeps retrying the connect"; finsd doubles its back-off from
// retry_min to retry_max and stays there, however long the outage.
TEST(TcpClient, RetryBackOffDoublesAndIsBounded) {
    const server::TcpClientTiming t;  // 100 ms .. 10 s
    using std::chrono::milliseconds;
    EXPECT_EQ(server::tcp_client_retry_delay(0, t), milliseconds(100));
    EXPECT_EQ(server::tcp_client_retry_delay(1, t), milliseconds(200));
    EXPECT_EQ(server::tcp_client_retry_delay(6, t), milliseconds(6400));
    EXPECT_EQ(server::tcp_client_retry_delay(7, t), milliseconds(10'000));
    EXPECT_EQ(server::tcp_client_retry_delay(4'000'000'000U, t), milliseconds(10'000));
}

}  // namespace
}  // namespace fins::test
