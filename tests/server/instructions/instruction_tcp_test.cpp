// Send/Rcv/SendCmd to a node that is this node's FINS/TCP client (instruction_udp.hpp):
// the command goes on that node's connection and its answer comes back on it (W421 7-4
// pairs each node with one connection; W596 3: with FINS/UDP off, the instructions need
// an established FINS/TCP connection).
#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <memory>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "fins/tcp.hpp"
#include "server/frame_builder.hpp"
#include "server/instructions/network_instructions.hpp"
#include "server/sessions/server.hpp"
#include "server/sessions/tcp_peer.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using server::InstructionKind;
using server::InstructionRequest;
using server::InstructionResult;

// finsd with FINS/UDP off, so FINS/TCP is the only way out, on its own I/O thread.
struct TcpOnlyNode {
    Harness h;
    asio::io_context io{1};
    std::unique_ptr<server::Server> server;
    std::thread thread;

    TcpOnlyNode() {
        auto started = start_tcp_only(io, h.plc);
        if (started) server = std::move(*started);
        thread = std::thread([this] { io.run(); });
    }
    ~TcpOnlyNode() {
        io.stop();
        thread.join();
    }
    // Starts `request` on the I/O thread; the future holds its result.
    std::future<InstructionResult> start(InstructionRequest request) {
        auto done = std::make_shared<std::promise<InstructionResult>>();
        auto result = done->get_future();
        asio::post(io, [this, request, done] {
            server->instructions().start(
                request, [done](const InstructionResult& r) { done->set_value(r); });
        });
        return result;
    }
};

InstructionRequest send_request(std::uint8_t node) {
    InstructionRequest r;
    r.kind = InstructionKind::send;
    r.destination = {0, node, 0};
    r.local = *parse_address("D100");
    r.remote = *parse_address("D200");
    r.count = 2;
    r.options.timeout = 20;  // 2.0 s (0.1 s units)
    r.options.retries = 0;
    return r;
}

TEST(InstructionsOverTcp, W596_3_SendToAFinsTcpClientNodeGoesOnItsConnection) {
    TcpOnlyNode n;
    ASSERT_NE(n.server, nullptr);
    ASSERT_EQ(n.h.send("0102 82006400 0002 1111 2222").end_code(), 0x0000);
    TcpPeer peer(n.server->tcp_port());
    ASSERT_TRUE(peer.handshake());

    auto result = n.start(send_request(peer.node()));
    const auto packet = peer.receive_packet();
    ASSERT_GE(packet.size(), tcp_header_size + 12u) << "no command on the connection";
    const std::vector<std::uint8_t> command(packet.begin() + tcp_header_size, packet.end());
    EXPECT_EQ(command[0], 0x80);         // ICF: a command, response required
    EXPECT_EQ(command[4], peer.node());  // DA1: the client's node
    EXPECT_EQ(command[10], 0x01);        // 01 02 MEMORY AREA WRITE of D200, 2 words
    EXPECT_EQ(command[11], 0x02);
    EXPECT_EQ(
        std::vector<std::uint8_t>(command.begin() + 12, command.end()),
        (std::vector<std::uint8_t>{0x82, 0x00, 0xC8, 0x00, 0x00, 0x02, 0x11, 0x11, 0x22, 0x22}));
    // The client answers as a CPU Unit does (frames 1.5): addresses swapped, SID echoed.
    const std::vector<std::uint8_t> answer{
        0xC0,       0x00,       0x02,       command[6], command[7], command[8], command[3],
        command[4], command[5], command[9], 0x01,       0x02,       0x00,       0x00};
    ASSERT_TRUE(peer.send_frame(answer));
    ASSERT_EQ(result.wait_for(std::chrono::seconds(5)), std::future_status::ready);
    const auto r = result.get();
    EXPECT_TRUE(r.done()) << r.detail;
    EXPECT_EQ(r.transmissions, 1u);
    EXPECT_EQ(r.end_code, 0x0000);
}

TEST(InstructionsOverTcp, W596_3_WithUdpOffANodeWithoutConnectionIsAnError) {
    TcpOnlyNode n;
    ASSERT_NE(n.server, nullptr);
    auto result = n.start(send_request(77));
    ASSERT_EQ(result.wait_for(std::chrono::seconds(5)), std::future_status::ready);
    const auto r = result.get();
    EXPECT_EQ(r.error_id, server::instruction_communications_error);
    EXPECT_EQ(r.error_id_ex, 0x0101);  // local node not in network
    EXPECT_NE(r.detail.find("no FINS/TCP connection"), std::string::npos) << r.detail;
}

}  // namespace
}  // namespace fins::test
