// FINS/UDP session (issue 6 item 12): batched receive and send, answers to each
// datagram's own sender, and a full send buffer that drops replies instead of blocking
// the one I/O thread every TCP session shares.
#include <gtest/gtest.h>

#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include <boost/asio/generic/datagram_protocol.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/post.hpp>

#include "fins/tcp.hpp"
#include "server/frame_builder.hpp"
#include "server/sessions/server.hpp"
#include "server/sessions/tcp_peer.hpp"
#include "server/sessions/udp_session.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using server::UdpSession;

std::vector<std::uint8_t> read_request(std::uint8_t sid) {
    FrameFields f;
    f.service_id = sid;
    return request_frame("0101 82000000 0001", f);
}

void set_timeouts(int fd, int seconds) {
    timeval tv{seconds, 0};
    ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    ::setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
}

// Both ends of an AF_UNIX datagram pair. Unlike UDP on loopback, where the receiver
// drops what does not fit and the sender's buffer is free again at once, a datagram
// stays charged to the sender's buffer until the peer reads it: with a small SO_SNDBUF
// the session meets a send buffer that stays full for as long as the peer does not read.
struct UnixPair {
    UnixPair() {
        if (::socketpair(AF_UNIX, SOCK_DGRAM, 0, fds.data()) != 0)
            throw std::runtime_error("socketpair");
        const int small = 4096;  // the kernel doubles it: a dozen replies or so
        ::setsockopt(fds[0], SOL_SOCKET, SO_SNDBUF, &small, sizeof small);
    }
    ~UnixPair() { close_peer(); }
    void close_peer() {
        if (fds[1] >= 0) ::close(fds[1]);
        fds[1] = -1;
    }
    // The server end, handed over to the session (which closes it).
    asio::generic::datagram_protocol::socket server_end(asio::io_context& io) {
        const int fd = fds[0];
        fds[0] = -1;
        return {io, asio::generic::datagram_protocol(AF_UNIX, 0), fd};
    }
    [[nodiscard]] int peer() const { return fds[1]; }
    std::array<int, 2> fds{-1, -1};
};

TEST(UdpSession, BatchAnswersEachDatagramToItsOwnSenderInOrder) {
    Harness h;
    asio::io_context io{1};
    asio::ip::udp::socket bound(io, {asio::ip::make_address("127.0.0.1"), 0});
    // Room for every request below at once, so none is lost before the session runs.
    bound.set_option(asio::socket_base::receive_buffer_size(1 << 20));
    auto session = std::make_shared<UdpSession>(std::move(bound), h.dispatcher);
    session->start();
    const asio::ip::udp::endpoint to{asio::ip::make_address("127.0.0.1"), session->local_port()};
    ASSERT_NE(to.port(), 0);

    // 3 peers x 48 requests, interleaved, all queued before the session runs: more than
    // one turn (rounds_per_turn batches of batch_size), so batches mix the senders.
    constexpr std::size_t peers = 3;
    constexpr std::size_t per_peer = 48;
    static_assert(peers * per_peer > UdpSession::batch_size * UdpSession::rounds_per_turn);
    std::vector<asio::ip::udp::socket> clients;
    for (std::size_t c = 0; c < peers; ++c)
        clients.emplace_back(io, asio::ip::udp::v4());
    for (std::size_t i = 0; i < per_peer; ++i)
        for (std::size_t c = 0; c < peers; ++c)
            clients[c].send_to(asio::buffer(read_request(static_cast<std::uint8_t>(c * 64 + i))),
                               to);

    std::vector<std::vector<std::uint8_t>> sids(peers);
    std::size_t total = 0;
    std::array<std::uint8_t, 64> in{};
    for (int spin = 0; spin < 2000 && total < peers * per_peer; ++spin) {
        io.run_one_for(std::chrono::milliseconds(10));
        for (std::size_t c = 0; c < peers; ++c) {
            ssize_t n = 0;
            while ((n = ::recv(clients[c].native_handle(), in.data(), in.size(), MSG_DONTWAIT)) >
                   0) {
                ASSERT_EQ(n, 16);  // header, command, end code, one word
                EXPECT_EQ((in[12] << 8) | in[13], 0x0000);
                sids[c].push_back(in[9]);
                ++total;
            }
        }
    }
    for (std::size_t c = 0; c < peers; ++c) {
        ASSERT_EQ(sids[c].size(), per_peer) << "peer " << c;
        for (std::size_t i = 0; i < per_peer; ++i)
            EXPECT_EQ(sids[c][i], c * 64 + i);
    }
    EXPECT_EQ(session->counters().received, peers * per_peer);
    EXPECT_EQ(session->counters().sent, peers * per_peer);
    EXPECT_EQ(session->counters().dropped, 0U);
    session->close();
}

TEST(UdpSession, FullSendBufferDropsRepliesWhileTcpKeepsBeingServed) {
    Harness h;
    asio::io_context io{1};
    auto tcp = start_tcp_only(io, h.plc);
    ASSERT_TRUE(tcp.has_value());
    UnixPair pair;
    auto session = std::make_shared<UdpSession>(pair.server_end(io), h.dispatcher);
    session->start();
    // The I/O thread; on any exit the peer goes first, so that even a session blocked
    // in a send (the bug this pins) wakes up and the thread can be joined.
    struct Running {
        asio::io_context& io;
        UnixPair& pair;
        std::thread thread;
        ~Running() {
            io.stop();
            pair.close_peer();
            thread.join();
        }
    } running{io, pair, std::thread([&] { io.run(); })};
    // Runs `f` on the I/O thread and waits for it (bounded): a synchronisation point.
    const auto on_io = [&](auto f) -> std::optional<decltype(f())> {
        auto done = std::make_shared<std::promise<decltype(f())>>();
        auto result = done->get_future();
        asio::post(io, [done, f] { done->set_value(f()); });
        if (result.wait_for(std::chrono::seconds(10)) != std::future_status::ready)
            return std::nullopt;
        return result.get();
    };

    // The UDP peer floods requests and never reads: its queue fills after a few replies.
    // A session that blocked on the full buffer would stop reading too, and these
    // (blocking, 5 s timeout) sends would fail.
    constexpr std::size_t flood = 200;
    set_timeouts(pair.peer(), 5);
    std::size_t flooded = 0;
    for (std::size_t i = 0; i < flood; ++i) {
        const auto frame = read_request(static_cast<std::uint8_t>(i));
        if (::send(pair.peer(), frame.data(), frame.size(), 0) ==
            static_cast<ssize_t>(frame.size()))
            ++flooded;
    }
    EXPECT_EQ(flooded, flood);

    // Meanwhile a FINS/TCP client on the same I/O thread is answered, request after request.
    const auto port = on_io([&] { return (*tcp)->tcp_port(); });
    ASSERT_TRUE(port.has_value()) << "the I/O thread is stuck";
    TcpPeer client(*port);
    ASSERT_TRUE(client.handshake());
    for (std::uint8_t sid = 1; sid <= 20; ++sid)
        EXPECT_EQ(client.read_word(sid), 0x0000);

    // Every request was read and either answered or dropped (none blocked, none refused).
    UdpSession::Counters counters;
    for (int i = 0; i < 1000 && counters.received < flood; ++i) {
        const auto now = on_io([&] { return session->counters(); });
        ASSERT_TRUE(now.has_value()) << "the I/O thread is stuck";
        counters = *now;
    }
    EXPECT_EQ(counters.received, flood);
    EXPECT_EQ(counters.sent + counters.dropped, flood);
    EXPECT_GT(counters.dropped, 0U);
    EXPECT_EQ(counters.failed, 0U);

    // What was sent is exactly what the peer finds queued; once it reads, UDP answers again.
    std::array<std::uint8_t, 64> in{};
    std::uint64_t queued = 0;
    while (::recv(pair.peer(), in.data(), in.size(), MSG_DONTWAIT) > 0)
        ++queued;
    EXPECT_EQ(queued, counters.sent);
    const auto last = read_request(0xEE);
    ASSERT_EQ(::send(pair.peer(), last.data(), last.size(), 0), static_cast<ssize_t>(last.size()));
    ASSERT_EQ(::recv(pair.peer(), in.data(), in.size(), 0), 16);
    EXPECT_EQ(in[9], 0xEE);
    ASSERT_TRUE(on_io([&] {
                    session->close();
                    (*tcp)->stop();
                    return true;
                }).has_value());
}

}  // namespace
}  // namespace fins::test
