// finsd's FINS/UDP side: one datagram is one FINS frame, and the answer goes to the
// datagram's source address and port (what CS/CJ Ethernet units do with the dynamic
// conversion method, frames section 2).
//
// Batched and never blocking, on the one I/O thread the whole server shares:
//   wait until readable -> recvmmsg() up to `batch_size` datagrams (MSG_DONTWAIT) ->
//   Dispatcher::handle each into its own reply slot -> one sendmmsg() for the replies ->
//   (udp_batch.hpp; on Windows recvfrom/sendto per datagram, docs/windows.md)
//   again until recvmmsg finds nothing (at most `rounds_per_turn` batches, then the
//   turn goes back to the other sessions and continues after them), then wait. A turn
//   that starts with a lone datagram waits at once (a client with one request in flight
//   sends its next only after this reply: the extra recvmmsg would find nothing).
// The batch buffers (128 KB) are allocated once per thread and shared by the sessions
// that thread serves, which take turns: a batch is received, answered and sent before
// another session's starts, and an answer that waits (defer()) copies what it keeps.
// The path allocates nothing per datagram, and a plant of 10,000 units one set of
// buffers, not 10,000.
//
// A full socket send buffer (sendmmsg would block) drops the replies that did not fit,
// as an Ethernet Unit whose send buffer is full does: FINS/UDP has no delivery
// guarantee, clients resend on their timeout, and no reply is worth stalling every other
// UDP peer and TCP session for. Drops are counted and logged at most once per interval.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>

#include "transport/socket_headers.hpp"

#include <boost/asio/generic/datagram_protocol.hpp>

#include "fins/frame.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/sessions/log_summary.hpp"
#include "server/sessions/recent_peers.hpp"
#include "server/sessions/udp_batch.hpp"
#include "transport/asio.hpp"

namespace fins::server {

// A deferred answer (a Serial Gateway port's) goes out later with one non-blocking
// sendto() to the request's source address; a full send buffer drops it like any reply.
class UdpSession final : public std::enable_shared_from_this<UdpSession>, private ReplyPath {
  public:
    static constexpr std::size_t batch_size = udp_batch::batch_size;
    static constexpr unsigned rounds_per_turn = 4;

    struct Counters {
        std::uint64_t received = 0;  // datagrams read
        std::uint64_t sent = 0;      // replies handed to the kernel
        std::uint64_t dropped = 0;   // replies dropped because the send buffer was full
        std::uint64_t failed = 0;    // replies the kernel refused (e.g. unreachable address)
    };

    // `socket` is bound and open: a UDP socket, or any datagram socket (tests use an
    // AF_UNIX pair to get a send buffer that stays full while the peer does not read).
    UdpSession(asio::generic::datagram_protocol::socket socket, Dispatcher& dispatcher);
    ~UdpSession();
    UdpSession(const UdpSession&) = delete;
    UdpSession& operator=(const UdpSession&) = delete;

    void start();
    void close();
    [[nodiscard]] bool open() const noexcept { return socket_.is_open(); }
    // The bound IPv4/IPv6 port, 0 when closed or not an IP socket.
    [[nodiscard]] std::uint16_t local_port() const noexcept;
    [[nodiscard]] const Counters& counters() const noexcept { return counters_; }
    // The peers heard from lately, with the node their last frame named (the page's list).
    [[nodiscard]] const RecentPeers& recent_peers() const noexcept { return peers_; }
    // Sends one datagram that is not a reply (a frame a plant relays to another
    // process); false when the kernel did not take it whole.
    bool send_to(Bytes frame, const sockaddr_in& to) noexcept;

    // PLC-initiated messages (network_instructions.hpp): every received frame whose ICF
    // response bit is set goes to `hook` instead of the dispatcher (which drops
    // responses); the hook returns false for an answer nobody waited for (dropped).
    // `peer` is the datagram's source address: an answer must come from the node's.
    using ResponseHook = std::function<bool(Bytes frame, const sockaddr* peer, socklen_t size)>;
    void set_response_hook(ResponseHook hook) { response_hook_ = std::move(hook); }
    // Sends one frame from this socket (the node's own port) to `to`, without blocking.
    // False when the kernel refused it or the send buffer is full.
    bool send_to(Bytes frame, const sockaddr* to, socklen_t to_size) noexcept;

    struct Slots;  // the per-batch buffers and message headers (one set per thread)

  private:
    void wait_readable();
    void on_readable();
    // Serves up to rounds_per_turn batches; false when the socket was found empty.
    bool serve_turn();
    // Receives, answers and sends one batch; returns the datagrams received (-1: none).
    int serve_batch();
    void send_replies(std::size_t count);
    void note_dropped(std::uint64_t count);
    Completion defer() override;
    void send_late(Bytes frame, const sockaddr_storage& peer, socklen_t size);

    asio::generic::datagram_protocol::socket socket_;
    Dispatcher& dispatcher_;
    Counters counters_;
    std::size_t current_ = 0;  // the datagram being dispatched (defer() answers it)
    ResponseHook response_hook_;
    LogSummary drops_logged_;  // one warning per interval (log_summary.hpp)
    RecentPeers peers_;
};

}  // namespace fins::server
