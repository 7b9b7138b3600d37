// finsd's FINS/TCP client connection to a server that is gone without closing
// (tcp_client.hpp): keep-alive on the socket, and a connection that leaves
// max_unanswered instruction frames in a row unanswered is closed and opened again.
// The server here accepts and completes the handshake, then reads nothing: what a
// powered-off PLC looks like to instructions (the kernel still ACKs on loopback, so
// keep-alive alone cannot be seen to fire here; its options are checked instead).
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <future>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "plc/plc.hpp"
#include "server/frame_builder.hpp"
#include "server/sessions/io_thread.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

// Accepts on 127.0.0.1, answers the node address request (client node 10, server node
// 5), then never reads again; keeps every connection open until destroyed.
class SilentServer {
  public:
    SilentServer() {
        listener_ = ::socket(AF_INET, SOCK_STREAM, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        socklen_t size = sizeof a;
        if (::bind(listener_, reinterpret_cast<sockaddr*>(&a), size) != 0 ||
            ::listen(listener_, 4) != 0 ||
            ::getsockname(listener_, reinterpret_cast<sockaddr*>(&a), &size) != 0)
            return;
        port_ = ntohs(a.sin_port);
        thread_ = std::thread([this] { run(); });
    }
    ~SilentServer() {
        stop_ = true;
        if (thread_.joinable()) thread_.join();
        for (int fd : connections_)
            ::close(fd);
        ::close(listener_);
    }
    SilentServer(const SilentServer&) = delete;
    SilentServer& operator=(const SilentServer&) = delete;

    [[nodiscard]] std::uint16_t port() const { return port_; }
    [[nodiscard]] int accepted() const { return accepted_; }

  private:
    void run() {
        // Bounded: at most 8 connections, and it ends with the test.
        while (!stop_ && accepted_ < 8) {
            pollfd p{listener_, POLLIN, 0};
            if (::poll(&p, 1, 20) <= 0) continue;
            const int fd = ::accept(listener_, nullptr, nullptr);
            if (fd < 0) continue;
            connections_.push_back(fd);
            std::array<std::uint8_t, 20> hello{};
            std::size_t got = 0;
            for (int i = 0; i < 100 && got < hello.size(); ++i) {
                pollfd q{fd, POLLIN, 0};
                if (::poll(&q, 1, 20) <= 0) continue;
                const auto n = ::read(fd, hello.data() + got, hello.size() - got);
                if (n <= 0) break;
                got += static_cast<std::size_t>(n);
            }
            if (got < hello.size()) continue;
            // FINS, length 16, command 1, error 0, client node 10, server node 5.
            const std::array<std::uint8_t, 24> answer{'F', 'I', 'N', 'S', 0, 0, 0, 16, 0, 0, 0, 1,
                                                      0,   0,   0,   0,   0, 0, 0, 10, 0, 0, 0, 5};
            if (::write(fd, answer.data(), answer.size()) != static_cast<ssize_t>(answer.size()))
                continue;
            ++accepted_;
        }
    }

    int listener_ = -1;
    std::uint16_t port_ = 0;
    std::atomic<bool> stop_{false};
    std::atomic<int> accepted_{0};
    std::vector<int> connections_;  // the thread's until joined
    std::thread thread_;
};

struct Node : IoThread {
    Harness plc;
    std::unique_ptr<server::Server> server;

    ~Node() { stop(); }
    void start(std::uint16_t remote_port) {
        server::ServerOptions o;
        o.port = 0;
        o.udp = false;
        o.node = 1;
        o.remotes = {server::RemoteNode{0, 5, "127.0.0.1", remote_port, true, 0}};
        o.tcp_client_timing.retry_min = std::chrono::milliseconds(10);
        o.tcp_client_timing.retry_max = std::chrono::milliseconds(50);
        auto started = server::Server::start(io, plc.plc, o);
        ASSERT_TRUE(started.has_value());
        server = std::move(*started);
        start_thread();
    }
    const server::TcpClient& client() { return *server->tcp_clients()[0]; }
    server::InstructionResult run(server::InstructionRequest request) {
        return IoThread::run(*server, std::move(request));
    }
};

server::InstructionRequest quick_send() {
    server::InstructionRequest r;
    r.kind = server::InstructionKind::send;
    r.destination = {0, 5, 0};
    r.local = *parse_address("D100");
    r.remote = *parse_address("D200");
    r.count = 1;
    r.options.timeout = 1;  // 0.1 s
    return r;
}

// W596 3 ends an unanswered Send with 0800 / 0205; three in a row on one connection
// (TcpClientTiming::max_unanswered, chosen: the seeds do not say what an NX does) close
// it and open it again, so a server that came back is reached without restarting finsd.
TEST(TcpClient, W596_3_ThreeResponseTimeoutsInARowReopenTheConnection) {
    SilentServer silent;
    ASSERT_NE(silent.port(), 0);
    Node n;
    n.start(silent.port());
    ASSERT_NE(n.server, nullptr);
    ASSERT_TRUE(n.wait([&] { return n.client().established(); }));
    for (int i = 0; i < 2; ++i) {
        const auto r = n.run(quick_send());
        EXPECT_EQ(r.error_id_ex, 0x0205) << r.detail;
    }
    EXPECT_EQ(n.on_io([&] { return n.client().counters().silent; }), 0u);
    EXPECT_EQ(silent.accepted(), 1);
    EXPECT_EQ(n.run(quick_send()).error_id_ex, 0x0205);
    EXPECT_EQ(n.on_io([&] { return n.client().counters().silent; }), 1u);
    ASSERT_TRUE(n.wait([&] { return n.client().counters().connects == 2; }));
    EXPECT_EQ(silent.accepted(), 2);
    EXPECT_TRUE(n.on_io([&] { return n.client().established(); }));
    EXPECT_EQ(n.on_io([&] { return n.client().counters().drops; }), 1u);
}

// Retries count too: one Send with 2 retries leaves 3 frames unanswered.
TEST(TcpClient, W596_3_UnansweredRetriesCountTowardsTheReopen) {
    SilentServer silent;
    Node n;
    n.start(silent.port());
    ASSERT_NE(n.server, nullptr);
    ASSERT_TRUE(n.wait([&] { return n.client().established(); }));
    auto r = quick_send();
    r.options.retries = 2;
    EXPECT_EQ(n.run(r).error_id_ex, 0x0205);
    EXPECT_EQ(n.on_io([&] { return n.client().counters().silent; }), 1u);
    ASSERT_TRUE(n.wait([&] { return n.client().counters().connects == 2; }));
}

// A server that vanishes without a FIN (power off, cable pulled) is noticed by TCP
// keep-alive within 10 + 5 x 4 = 30 s, and unacknowledged frames by TCP_USER_TIMEOUT.
TEST(TcpClient, KeepAliveIsOnTheClientConnection) {
    SilentServer silent;
    Node n;
    n.start(silent.port());
    ASSERT_NE(n.server, nullptr);
    ASSERT_TRUE(n.wait([&] { return n.client().established(); }));
    const int fd = n.on_io([&] { return n.client().native_handle(); });
    ASSERT_GE(fd, 0);
    const auto option = [fd](int level, int name) {
        int value = -1;
        socklen_t size = sizeof value;
        EXPECT_EQ(::getsockopt(fd, level, name, &value, &size), 0);
        return value;
    };
    EXPECT_EQ(option(SOL_SOCKET, SO_KEEPALIVE), 1);
    EXPECT_EQ(option(IPPROTO_TCP, TCP_KEEPIDLE), 10);
    EXPECT_EQ(option(IPPROTO_TCP, TCP_KEEPINTVL), 5);
    EXPECT_EQ(option(IPPROTO_TCP, TCP_KEEPCNT), 4);
    EXPECT_EQ(option(IPPROTO_TCP, TCP_USER_TIMEOUT), 30'000);
}

}  // namespace
}  // namespace fins::test
