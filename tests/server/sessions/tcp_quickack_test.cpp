// FINS/TCP prompt acknowledgement (issue 6 item 13). A client that writes the 16-byte
// FINS/TCP header and the frame in two writes without TCP_NODELAY holds the frame
// (Nagle) until the header is acknowledged; Linux delays that ACK by ~40 ms once a
// server answers promptly (its "pingpong" mode). finsd re-arms TCP_QUICKACK after a
// read that no answer follows. The tests pin that on the server's own socket, without
// timing: the I/O thread is this one, so "the server has handled the read" is a fact.
#include <gtest/gtest.h>

#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstring>
#include <memory>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "fins/tcp.hpp"
#include "server/frame_builder.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

int quick_ack(int fd) {
    int value = -1;
    socklen_t len = sizeof value;
    if (::getsockopt(fd, IPPROTO_TCP, TCP_QUICKACK, &value, &len) != 0) return -1;
    return value;
}

std::size_t readable(int fd) {
    int n = 0;
    return ::ioctl(fd, FIONREAD, &n) == 0 ? static_cast<std::size_t>(n) : 0;
}

bool same(const sockaddr_in& a, const sockaddr_in& b) {
    return a.sin_family == b.sin_family && a.sin_port == b.sin_port &&
           a.sin_addr.s_addr == b.sin_addr.s_addr;
}

// The server's end of `client`'s connection: same process, so one of our descriptors.
int server_end_of(int client) {
    sockaddr_in local{};
    sockaddr_in remote{};
    socklen_t len = sizeof local;
    ::getsockname(client, reinterpret_cast<sockaddr*>(&local), &len);
    len = sizeof remote;
    ::getpeername(client, reinterpret_cast<sockaddr*>(&remote), &len);
    for (int fd = 0; fd < 4096; ++fd) {
        if (fd == client) continue;
        sockaddr_in a{};
        sockaddr_in b{};
        socklen_t la = sizeof a;
        socklen_t lb = sizeof b;
        if (::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &la) != 0 ||
            ::getpeername(fd, reinterpret_cast<sockaddr*>(&b), &lb) != 0)
            continue;
        if (same(a, remote) && same(b, local)) return fd;
    }
    return -1;
}

class TcpQuickAck : public ::testing::Test {
  protected:
    void SetUp() override {
        server::ServerOptions options;
        options.port = 0;
        options.udp = false;
        auto started = server::Server::start(io_, h_.plc, options);
        ASSERT_TRUE(started.has_value());
        server_ = std::move(*started);

        // A client as the issue describes it: no TCP_NODELAY.
        client_ = ::socket(AF_INET, SOCK_STREAM, 0);
        timeval tv{5, 0};
        ::setsockopt(client_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
        sockaddr_in to{};
        to.sin_family = AF_INET;
        to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        to.sin_port = htons(server_->tcp_port());
        ASSERT_EQ(::connect(client_, reinterpret_cast<sockaddr*>(&to), sizeof to), 0);

        std::array<std::uint8_t, 20> hello{};
        ByteWriter w{hello};
        write_node_address_request(w, 0);
        ASSERT_EQ(::send(client_, hello.data(), w.size(), 0), static_cast<ssize_t>(w.size()));
        ASSERT_TRUE(pump([&] { return readable(client_) >= 24; }));
        std::array<std::uint8_t, 24> answer{};
        ASSERT_EQ(::recv(client_, answer.data(), answer.size(), 0), 24);
        node_ = answer[19];
        server_fd_ = server_end_of(client_);
        ASSERT_GE(server_fd_, 0);
    }
    void TearDown() override {
        if (client_ >= 0) ::close(client_);
        if (server_) server_->stop();
    }

    // Runs the server (on this thread) until `done` holds, bounded in count and time.
    template <typename Done>
    bool pump(Done done) {
        for (int i = 0; i < 500 && !done(); ++i)
            io_.run_one_for(std::chrono::milliseconds(10));
        io_.poll();  // handlers the last reactor pass completed
        return done();
    }

    std::vector<std::uint8_t> frame(std::uint8_t sid, std::uint8_t icf = 0x80) const {
        FrameFields f;
        f.icf = icf;
        f.service_id = sid;
        f.destination = {0, 0, 0};
        f.source = {0, node_, 0};
        return request_frame("0101 82000000 0001", f);
    }

    // Puts the server's socket in the state it is in after a prompt answer (delayed
    // ACKs), sends `bytes`, lets the server read them and returns its TCP_QUICKACK.
    int quick_ack_after_reading(const std::uint8_t* bytes, std::size_t size) {
        const int off = 0;
        if (::setsockopt(server_fd_, IPPROTO_TCP, TCP_QUICKACK, &off, sizeof off) != 0 ||
            quick_ack(server_fd_) != 0)
            return -1;
        if (::send(client_, bytes, size, 0) != static_cast<ssize_t>(size)) return -1;
        pollfd arrived{server_fd_, POLLIN, 0};
        if (::poll(&arrived, 1, 5000) != 1) return -1;  // in the server's socket, unread
        if (!pump([&] { return readable(server_fd_) == 0; })) return -1;
        return quick_ack(server_fd_);
    }

    // Sends one whole request and returns its answer's end code (0xFFFF: none).
    std::uint16_t round_trip(std::uint8_t sid) {
        const auto request = frame(sid);
        std::vector<std::uint8_t> packet(tcp_header_size + request.size());
        ByteWriter w{packet};
        write_tcp_header(w, TcpCommand::frame, request.size());
        w.bytes(request);
        if (::send(client_, packet.data(), packet.size(), 0) != static_cast<ssize_t>(packet.size()))
            return 0xFFFF;
        return answer(sid);
    }

    std::uint16_t answer(std::uint8_t sid) {
        if (!pump([&] { return readable(client_) >= tcp_header_size + 16; })) return 0xFFFF;
        std::array<std::uint8_t, tcp_header_size + 16> in{};
        if (::recv(client_, in.data(), in.size(), 0) != static_cast<ssize_t>(in.size()) ||
            in[tcp_header_size + 9] != sid)
            return 0xFFFF;
        return static_cast<std::uint16_t>((in[tcp_header_size + 12] << 8) |
                                          in[tcp_header_size + 13]);
    }

    Harness h_;
    asio::io_context io_{1};
    std::unique_ptr<server::Server> server_;
    int client_ = -1;
    int server_fd_ = -1;
    std::uint8_t node_ = 0;
};

// The split-write client: the header alone arrives first. Once finsd has read it, the
// ACK the client waits for must not be delayed.
TEST_F(TcpQuickAck, ReArmedAfterAReadThatEndsInsideAPacket) {
    for (std::uint8_t sid = 1; sid <= 3; ++sid) {
        const auto request = frame(sid);
        std::array<std::uint8_t, tcp_header_size> header{};
        ByteWriter w{header};
        write_tcp_header(w, TcpCommand::frame, request.size());
        EXPECT_EQ(quick_ack_after_reading(header.data(), header.size()), 1) << int{sid};
        // The second write: the frame; the answer follows.
        ASSERT_EQ(::send(client_, request.data(), request.size(), 0),
                  static_cast<ssize_t>(request.size()));
        EXPECT_EQ(answer(sid), 0x0000);
    }
}

// ICF bit 0 (fins-frames.md 1.2): a request that asks for no response gets none, so no
// answer carries the ACK either: the client's next write would wait for it.
TEST_F(TcpQuickAck, ReArmedAfterAFrameThatAsksForNoResponse) {
    const auto request = frame(0x21, 0x81);
    std::vector<std::uint8_t> packet(tcp_header_size + request.size());
    ByteWriter w{packet};
    write_tcp_header(w, TcpCommand::frame, request.size());
    w.bytes(request);
    EXPECT_EQ(quick_ack_after_reading(packet.data(), packet.size()), 1);
    EXPECT_EQ(readable(client_), 0U);  // no answer
    EXPECT_EQ(round_trip(0x22), 0x0000);
}

}  // namespace
}  // namespace fins::test
