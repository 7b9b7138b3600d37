// UdpSession: batched FINS/UDP (see udp_session.hpp for the path and the drop policy).
#include "server/sessions/udp_session.hpp"

#include <netinet/in.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

#include "server/dispatch/dispatcher.hpp"
#include "server/sessions/failure_boundary.hpp"
#include "server/metrics/metrics.hpp"
#include "transport/asio.hpp"

namespace fins::server {

namespace {

// A datagram one byte longer than the largest frame is still received long enough for
// the dispatcher to answer 1001 instead of seeing a silently truncated frame.
constexpr std::size_t receive_size = max_frame_size + 1;

bool would_block(int error) noexcept {
    return error == EAGAIN || error == EWOULDBLOCK;
}

}  // namespace

// recvmmsg/sendmmsg take arrays of message headers that point at the buffers; they are
// wired once here and only the lengths and reply addresses change per batch.
struct UdpSession::Slots {
    // Not zeroed: only received bytes and written replies are ever read, so the pages of
    // the 128 KB buffers are backed only once datagrams use them. One set per thread,
    // not per session: a plant of 10,000 units had 10,000 (issue 19; docs/benchmarks.md).
    std::array<std::array<std::uint8_t, receive_size>, batch_size> in;
    std::array<std::array<std::uint8_t, max_frame_size>, batch_size> out;
    std::array<sockaddr_storage, batch_size> peers{};
    std::array<iovec, batch_size> in_iov{};
    std::array<iovec, batch_size> out_iov{};
    std::array<mmsghdr, batch_size> in_msgs{};
    std::array<mmsghdr, batch_size> out_msgs{};

    Slots() noexcept {
        for (std::size_t i = 0; i < batch_size; ++i) {
            in_iov[i] = {in[i].data(), in[i].size()};
            in_msgs[i].msg_hdr.msg_name = &peers[i];
            in_msgs[i].msg_hdr.msg_iov = &in_iov[i];
            in_msgs[i].msg_hdr.msg_iovlen = 1;
            out_iov[i] = {out[i].data(), 0};
            out_msgs[i].msg_hdr.msg_iov = &out_iov[i];
            out_msgs[i].msg_hdr.msg_iovlen = 1;
        }
    }
};

namespace {

// The batch buffers of the sessions this thread serves (udp_session.hpp): one batch is
// served to its end before the next session's starts, and nothing in it waits.
UdpSession::Slots& thread_slots() {
    thread_local const std::unique_ptr<UdpSession::Slots> slots =
        std::make_unique<UdpSession::Slots>();
    return *slots;
}

}  // namespace

UdpSession::UdpSession(asio::generic::datagram_protocol::socket socket, Dispatcher& dispatcher)
    : socket_(std::move(socket)), dispatcher_(dispatcher) {}

UdpSession::~UdpSession() = default;

void UdpSession::start() {
    wait_readable();
}

void UdpSession::close() {
    boost::system::error_code ignored;
    socket_.close(ignored);
}

std::uint16_t UdpSession::local_port() const noexcept {
    boost::system::error_code ec;
    if (!socket_.is_open()) return 0;
    const auto endpoint = socket_.local_endpoint(ec);
    if (ec) return 0;
    const sockaddr* address = endpoint.data();
    if (address->sa_family == AF_INET && endpoint.size() >= sizeof(sockaddr_in)) {
        sockaddr_in in4{};
        std::memcpy(&in4, address, sizeof in4);
        return ntohs(in4.sin_port);
    }
    if (address->sa_family == AF_INET6 && endpoint.size() >= sizeof(sockaddr_in6)) {
        sockaddr_in6 in6{};
        std::memcpy(&in6, address, sizeof in6);
        return ntohs(in6.sin6_port);
    }
    return 0;
}

void UdpSession::wait_readable() {
    socket_.async_wait(asio::socket_base::wait_read,
                       [self = shared_from_this()](boost::system::error_code ec) {
                           if (ec == asio::error::operation_aborted || !self->open()) return;
                           if (ec) spdlog::debug("fins/udp: wait: {}", ec.message());
                           self->on_readable();
                       });
}

void UdpSession::on_readable() {
    if (!serve_turn()) {
        // Drained. Asio re-arms the descriptor for a wait (EPOLL_CTL_MOD), which also
        // reports a datagram that arrived in between: no wake-up is lost.
        wait_readable();
        return;
    }
    // More datagrams are queued: let the other sessions' ready handlers run first, then
    // go on without waiting for readiness (the reactor is edge-triggered).
    asio::post(socket_.get_executor(), [self = shared_from_this()] {
        if (self->open()) self->on_readable();
    });
}

bool UdpSession::serve_turn() {
    // Read again until the socket is empty, even after a short batch: with requests in
    // flight the next ones arrive while a batch is answered, and finding them here
    // costs less than a trip through the reactor (measured, docs/benchmarks.md).
    // A lone datagram is the one-in-flight client: the next cannot come before it has
    // this reply, so looking again would only find nothing; the reactor's re-arm
    // (EPOLL_CTL_MOD) reports a datagram that does come meanwhile.
    for (unsigned round = 0; round < rounds_per_turn; ++round) {
        const int received = serve_batch();
        if (received < 0 || (round == 0 && received == 1)) return false;
    }
    return true;
}

int UdpSession::serve_batch() {
    Slots& s = thread_slots();
    for (auto& m : s.in_msgs)
        m.msg_hdr.msg_namelen = sizeof(sockaddr_storage);
    const int received =
        ::recvmmsg(socket_.native_handle(), s.in_msgs.data(), batch_size, MSG_DONTWAIT, nullptr);
    if (received <= 0) {
        // EAGAIN: drained. Anything else (an error queued on the socket, which reading
        // clears): log it and wait for readiness again, UDP keeps being served.
        if (received < 0 && !would_block(errno) && errno != EINTR)
            spdlog::debug("fins/udp: receive: {}", std::strerror(errno));
        return -1;
    }
    counters_.received += static_cast<std::uint64_t>(received);

    // One clock reading per batch: its datagrams arrived within microseconds.
    RequestContext context{Link::udp, std::chrono::system_clock::now(), this};
    unsigned replies = 0;
    for (int i = 0; i < received; ++i) {
        current_ = static_cast<std::size_t>(i);
        const auto& request = s.in_msgs[static_cast<std::size_t>(i)];
        context.peer = &s.peers[static_cast<std::size_t>(i)];
        // A longer datagram was cut to receive_size (MSG_TRUNC), still more than a frame.
        const std::size_t size = std::min<std::size_t>(request.msg_len, receive_size);
        const Bytes frame{s.in[static_cast<std::size_t>(i)].data(), size};
        if (size >= header_size) peers_.note(*context.peer, frame[7], context.now);  // [7]: SA1
        // An answer to one of this node's own Send/Rcv/SendCmd instructions.
        // One it did not wait for goes on to the dispatcher: in a plant the router
        // relays answers for other nodes; a single node drops them there.
        if (response_hook_ && size > 0 && (frame[0] & icf_response) != 0 &&
            take_response_guarded([&] {
                return response_hook_(frame, reinterpret_cast<const sockaddr*>(context.peer),
                                      request.msg_hdr.msg_namelen);
            }))
            continue;
        const std::size_t n = handle_guarded(
            dispatcher_, Bytes{s.in[static_cast<std::size_t>(i)].data(), size}, s.out[replies],
            context);
        if (n == 0) continue;
        s.out_iov[replies].iov_len = n;
        auto& reply = s.out_msgs[replies].msg_hdr;
        reply.msg_name = &s.peers[static_cast<std::size_t>(i)];
        reply.msg_namelen = s.peers[static_cast<std::size_t>(i)].ss_family == AF_INET
                                ? static_cast<socklen_t>(sizeof(sockaddr_in))
                                : request.msg_hdr.msg_namelen;
        ++replies;
    }
    if (replies > 0) send_replies(replies);
    return received;
}

void UdpSession::send_replies(unsigned count) {
    Slots& s = thread_slots();
    unsigned done = 0;
    // Each pass sends at least one reply or gives up on one; EINTR retries are bounded.
    for (unsigned attempt = 0; done < count && attempt < 2 * batch_size; ++attempt) {
        const int sent = ::sendmmsg(socket_.native_handle(), &s.out_msgs[done], count - done,
                                    MSG_DONTWAIT | MSG_NOSIGNAL);
        if (sent > 0) {
            done += static_cast<unsigned>(sent);
            counters_.sent += static_cast<std::uint64_t>(sent);
            continue;
        }
        const int error = errno;
        if (error == EINTR) continue;
        if (would_block(error) || error == ENOBUFS) break;  // the send buffer is full
        // This one reply cannot go out (e.g. a source address one cannot send to): skip it.
        spdlog::debug("fins/udp: reply dropped: {}", std::strerror(error));
        ++counters_.failed;
        ++done;
    }
    if (done < count) note_dropped(count - done);
}

bool UdpSession::send_to(Bytes frame, const sockaddr_in& to) noexcept {
    return send_to(frame, reinterpret_cast<const sockaddr*>(&to), sizeof to);
}

bool UdpSession::send_to(Bytes frame, const sockaddr* to, socklen_t to_size) noexcept {
    for (int attempt = 0; attempt < 4; ++attempt) {
        const auto n = ::sendto(socket_.native_handle(), frame.data(), frame.size(),
                                MSG_DONTWAIT | MSG_NOSIGNAL, to, to_size);
        if (n >= 0) return true;
        if (errno != EINTR) break;
    }
    spdlog::debug("fins/udp: instruction frame not sent: {}", std::strerror(errno));
    return false;
}

Completion UdpSession::defer() {
    // Called while serve_batch dispatches datagram current_, on this thread.
    const Slots& s = thread_slots();
    const auto& request = s.in_msgs[current_];
    return [weak = weak_from_this(), peer = s.peers[current_],
            size = request.msg_hdr.msg_namelen](Bytes frame) {
        if (auto self = weak.lock(); self && self->open()) self->send_late(frame, peer, size);
    };
}

void UdpSession::send_late(Bytes frame, const sockaddr_storage& peer, socklen_t size) {
    const auto sent =
        ::sendto(socket_.native_handle(), frame.data(), frame.size(), MSG_DONTWAIT | MSG_NOSIGNAL,
                 reinterpret_cast<const sockaddr*>(&peer), size);
    if (sent >= 0) {
        ++counters_.sent;
        return;
    }
    if (would_block(errno) || errno == ENOBUFS) {
        note_dropped(1);
        return;
    }
    spdlog::debug("fins/udp: late reply dropped: {}", std::strerror(errno));
    ++counters_.failed;
}

void UdpSession::note_dropped(std::uint64_t count) {
    counters_.dropped += count;
    metrics::note_datagrams_dropped(count);
    if (const auto n = drops_logged_.note(count))
        spdlog::warn("fins/udp: send buffer full, {} replies dropped (clients resend on timeout)",
                     n);
}

}  // namespace fins::server
