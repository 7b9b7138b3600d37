// UdpSession: batched FINS/UDP (see udp_session.hpp for the path and the drop policy).
#include "server/sessions/udp_session.hpp"

#include "transport/socket_headers.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>

#include "server/dispatch/dispatcher.hpp"
#include "server/metrics/metrics.hpp"
#include "server/sessions/failure_boundary.hpp"
#include "server/sessions/udp_batch.hpp"
#include "transport/asio.hpp"

namespace fins::server {

// The batch buffers (udp_batch.hpp) of the sessions this thread serves.
struct UdpSession::Slots : udp_batch::Batch {};

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
    udp_batch::prepare(socket_.native_handle());
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
    const std::size_t received = udp_batch::receive(socket_.native_handle(), s);
    if (received == 0) return -1;
    counters_.received += received;

    // One clock reading per batch: its datagrams arrived within microseconds.
    RequestContext context{Link::udp, std::chrono::system_clock::now(), this};
    std::size_t replies = 0;
    for (std::size_t i = 0; i < received; ++i) {
        current_ = i;
        context.peer = &s.peer[i];
        const Bytes frame{s.in[i].data(), s.in_size[i]};
        if (frame.size() >= header_size)
            peers_.note(*context.peer, frame[7], context.now);  // [7]: SA1
        // An answer to one of this node's own Send/Rcv/SendCmd instructions.
        // One it did not wait for goes on to the dispatcher: in a plant the router
        // relays answers for other nodes; a single node drops them there.
        if (response_hook_ && !frame.empty() && (frame[0] & icf_response) != 0 &&
            take_response_guarded([&] {
                return response_hook_(frame, reinterpret_cast<const sockaddr*>(context.peer),
                                      s.peer_size[i]);
            }))
            continue;
        const std::size_t n = handle_guarded(dispatcher_, frame, s.out[replies], context);
        if (n == 0) continue;
        s.out_size[replies] = n;
        s.out_peer[replies] = i;
        ++replies;
    }
    if (replies > 0) send_replies(replies);
    return static_cast<int>(received);
}

void UdpSession::send_replies(std::size_t count) {
    const auto r = udp_batch::send(socket_.native_handle(), thread_slots(), count);
    counters_.sent += r.sent;
    counters_.failed += r.failed;
    if (r.dropped > 0) note_dropped(r.dropped);
}

bool UdpSession::send_to(Bytes frame, const sockaddr_in& to) noexcept {
    return send_to(frame, reinterpret_cast<const sockaddr*>(&to), sizeof to);
}

bool UdpSession::send_to(Bytes frame, const sockaddr* to, socklen_t to_size) noexcept {
    return udp_batch::send_one(socket_.native_handle(), frame.data(), frame.size(), to, to_size) ==
           udp_batch::SendOne::sent;
}

Completion UdpSession::defer() {
    // Called while serve_batch dispatches datagram current_, on this thread.
    const Slots& s = thread_slots();
    return [weak = weak_from_this(), peer = s.peer[current_],
            size = s.peer_size[current_]](Bytes frame) {
        if (auto self = weak.lock(); self && self->open()) self->send_late(frame, peer, size);
    };
}

void UdpSession::send_late(Bytes frame, const sockaddr_storage& peer, socklen_t size) {
    switch (udp_batch::send_one(socket_.native_handle(), frame.data(), frame.size(),
                                reinterpret_cast<const sockaddr*>(&peer), size)) {
        case udp_batch::SendOne::sent:
            ++counters_.sent;
            break;
        case udp_batch::SendOne::full:
            note_dropped(1);
            break;
        case udp_batch::SendOne::failed:
            ++counters_.failed;
            break;
    }
}

void UdpSession::note_dropped(std::uint64_t count) {
    counters_.dropped += count;
    metrics::note_datagrams_dropped(count);
    if (const auto n = drops_logged_.note(count))
        spdlog::warn("fins/udp: send buffer full, {} replies dropped (clients resend on timeout)",
                     n);
}

}  // namespace fins::server
