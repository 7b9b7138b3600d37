// FINS/TCP prompt acknowledgement (issue 6 item 13). A client that writes the 16-byte
// FINS/TCP header and the frame in two writes without TCP_NODELAY holds the frame
// (Nagle) until the header is acknowledged; Linux delays that ACK by ~40 ms once a
// server answers promptly (its "pingpong" mode). finsd re-arms TCP_QUICKACK after every
// read. The test pins that re-arming on the server's own socket, without timing: the
// I/O thread is this one, so "the server has handled the read" is a fact, not a wait.
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
#include <vector>

#include <asio/io_context.hpp>

#include "fins/tcp.hpp"
#include "server/frame_builder.hpp"
#include "server/server.hpp"

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

TEST(TcpSession, QuickAckIsReArmedAfterEveryRead) {
    Harness h;
    asio::io_context io{1};
    server::ServerOptions options;
    options.port = 0;
    options.udp = false;
    auto server = server::Server::start(io, h.plc, options);
    ASSERT_TRUE(server.has_value());

    // A client as the issue describes it: no TCP_NODELAY.
    const int client = ::socket(AF_INET, SOCK_STREAM, 0);
    timeval tv{5, 0};
    ::setsockopt(client, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to.sin_port = htons((*server)->tcp_port());
    ASSERT_EQ(::connect(client, reinterpret_cast<sockaddr*>(&to), sizeof to), 0);
    // Runs the server until `done` holds (bounded in count and time).
    const auto pump = [&](auto done) {
        for (int i = 0; i < 500 && !done(); ++i) io.run_one_for(std::chrono::milliseconds(10));
        io.poll();  // handlers the last reactor pass completed
        return done();
    };

    std::array<std::uint8_t, 64> buf{};
    ByteWriter hs{buf};
    write_node_address_request(hs, 0);
    ASSERT_EQ(::send(client, buf.data(), hs.size(), 0), static_cast<ssize_t>(hs.size()));
    ASSERT_TRUE(pump([&] { return readable(client) >= 24; }));
    ASSERT_EQ(::recv(client, buf.data(), 24, 0), 24);
    const std::uint8_t node = buf[19];
    const int server_fd = server_end_of(client);
    ASSERT_GE(server_fd, 0);

    for (std::uint8_t sid = 1; sid <= 3; ++sid) {
        FrameFields f;
        f.service_id = sid;
        f.destination = {0, 0, 0};
        f.source = {0, node, 0};
        const auto frame = request_frame("0101 82000000 0001", f);
        std::array<std::uint8_t, tcp_header_size> header{};
        ByteWriter w{header};
        write_tcp_header(w, TcpCommand::frame, frame.size());

        // As after an answer sent promptly: the kernel delays its ACKs.
        const int off = 0;
        ASSERT_EQ(::setsockopt(server_fd, IPPROTO_TCP, TCP_QUICKACK, &off, sizeof off), 0);
        ASSERT_EQ(quick_ack(server_fd), 0);

        // The client's first write: the header alone. Once finsd has read it, its ACK
        // must not wait: quick-ack mode is on again.
        ASSERT_EQ(::send(client, header.data(), header.size(), 0), static_cast<ssize_t>(header.size()));
        pollfd arrived{server_fd, POLLIN, 0};
        ASSERT_EQ(::poll(&arrived, 1, 5000), 1);  // in the server's socket, not yet read
        ASSERT_TRUE(pump([&] { return readable(server_fd) == 0; }));
        EXPECT_EQ(quick_ack(server_fd), 1) << "request " << int{sid};

        // The second write: the frame; the answer follows.
        ASSERT_EQ(::send(client, frame.data(), frame.size(), 0), static_cast<ssize_t>(frame.size()));
        ASSERT_TRUE(pump([&] { return readable(client) >= tcp_header_size + 16; }));
        std::array<std::uint8_t, tcp_header_size + 16> answer{};
        ASSERT_EQ(::recv(client, answer.data(), answer.size(), 0), static_cast<ssize_t>(answer.size()));
        EXPECT_EQ(answer[tcp_header_size + 9], sid);
        EXPECT_EQ((answer[tcp_header_size + 12] << 8) | answer[tcp_header_size + 13], 0x0000);
    }
    ::close(client);
    (*server)->stop();
}

}  // namespace
}  // namespace fins::test
