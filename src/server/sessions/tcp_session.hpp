// One FINS/TCP connection on the server side (frames section 3.4, W421 7-4):
//   1. the client sends NODE ADDRESS DATA SEND (command 0) with its node, 0 = allocate;
//   2. we answer command 1 with the client node and ours, or an error code and close;
//   3. then FRAME SEND (command 2) packets carry FINS frames both ways.
// A bad envelope (magic, length, unknown or out-of-sequence command) is answered with
// FRAME SEND ERROR NOTIFICATION (command 3) and the connection is closed.
//
// Identity: the node of step 2 is the connection's identity. A frame whose source
// (SNA, SA1) is not this node on the local network is neither executed nor answered
// (W421 pairs each node with one connection and sends a node's answers on its own
// connection only; see docs/finsd.md "FINS/TCP identity and limits").
//
// Closing after an error notice: shut down our sending side, read and discard what
// the peer still sends (bounded in bytes and time), then close; closing with unread
// input makes the kernel send a reset that can destroy the notice in flight.
//
// Limits (TcpLimits): a deadline for the handshake (from accept), for a packet once its
// first byte arrived and for a response to be taken by the peer, an idle timeout and TCP
// keep-alive. The server caps connections that have not finished the handshake.
//
// The request path does its own non-blocking I/O, as UdpSession does (issue 6 item 12):
//   wait until readable (Asio) -> recv() what is there -> answer every complete packet,
//   each with one send() of its own -> recv() again while requests keep coming (at most
//   `rounds_per_turn` reads, then the other sessions' turn) -> wait again.
// Asio's own reads and writes cost two extra polls of the reactor per request. Only an
// answer the kernel does not take at once (a full send buffer) goes through an
// asynchronous write; reading stops until it is written.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "fins/error.hpp"
#include "fins/tcp.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/sessions/tcp_limits.hpp"
#include "server/sessions/tcp_node_table.hpp"
#include "transport/asio.hpp"

namespace fins::server {

// Turns TCP keep-alive on `socket` on with `idle` (see TcpLimits::keepalive) or off (0).
boost::system::error_code set_keepalive(asio::ip::tcp::socket& socket,
                                        std::chrono::seconds idle) noexcept;

// Deferred answers (a Serial Gateway port's) wait in a small queue of their own and are
// written whole between the in-order responses, never interleaved with one.
class TcpSession final : public std::enable_shared_from_this<TcpSession>, private ReplyPath {
  public:
    TcpSession(asio::ip::tcp::socket socket, Dispatcher& dispatcher, TcpNodeTable& nodes,
               const TcpLimits& limits);
    ~TcpSession();
    TcpSession(const TcpSession&) = delete;
    TcpSession& operator=(const TcpSession&) = delete;

    void start();
    // Closes at once (no notice): shutdown, timeouts, eviction.
    void close();
    [[nodiscard]] bool open() const noexcept { return state_ != State::closed; }
    // The client node the handshake gave this connection; 0 before it.
    [[nodiscard]] std::uint8_t client_node() const noexcept { return client_node_; }
    // Accepted but not established: still in the handshake, or draining after a refusal.
    [[nodiscard]] bool pending() const noexcept {
        return state_ == State::handshake || state_ == State::draining;
    }
    // W421 7-4: another client from the same IP address asked for this connection's node.
    // Sends CONNECTION CONFIRMATION (command 6): a live peer acknowledges it, a gone one
    // answers with a reset and the read or write that sees it closes this session.
    void confirm_connection();
    [[nodiscard]] const asio::ip::address& peer_address() const noexcept { return peer_; }
    [[nodiscard]] std::uint16_t peer_port() const noexcept { return peer_port_; }
    // Sends a FINS frame that answers no request of this connection's read loop (in a
    // plant: an answer routed back from another process to this client's node). Queued
    // behind a write in progress, never interleaved; false when the connection is not
    // established or max_late frames already wait (the frame is dropped, as a full
    // send buffer drops a datagram). The same queue as the Serial Gateway's late answers.
    bool push_frame(Bytes frame);
    // A response frame (ICF bit 6) from the client is offered to `hook` first (this
    // node's Send/Rcv/SendCmd waiting for it); one it does not take goes on to the
    // dispatcher, as on FINS/UDP.
    void set_response_hook(std::function<bool(Bytes)> hook) { response_hook_ = std::move(hook); }

  private:
    enum class State : std::uint8_t { handshake, established, draining, closed };
    enum class Deadline : std::uint8_t { handshake, frame, idle, drain };
    using Clock = std::chrono::steady_clock;

    void wait_readable();
    void on_readable();
    // Answers the complete packets in in_ and keeps the partial one. False when serving
    // must stop: an answer waits for an asynchronous write (whose completion resumes)
    // or the connection is closing.
    bool serve_buffered();
    // After an asynchronous write: serve what is buffered, then read again.
    void resume();
    // Sends the first `size` bytes of out_ now when nothing else is being written. False
    // when serving must stop (see serve_buffered).
    bool send_answer(std::size_t size, bool close_after);
    // Returns false when the connection must close after `out_` is written.
    bool handle_packet(const TcpPacket& packet);
    bool handshake(const TcpPacket& packet);
    // True when the frame's source is this connection's node on the local network.
    [[nodiscard]] bool from_bound_node(Bytes frame) const noexcept;
    void send_and_continue(std::size_t size, bool close_after);
    void send_confirmation();
    void close_after_notice();
    void drain();
    Completion defer() override;
    void queue_late(Bytes frame);
    void write_late();

    void set_deadline(Deadline kind, Clock::duration after);
    void arm_timer(Clock::time_point at);
    void on_timer();

    asio::ip::tcp::socket socket_;
    Dispatcher& dispatcher_;
    TcpNodeTable& nodes_;
    const TcpLimits& limits_;
    asio::steady_timer timer_;
    asio::ip::address peer_;
    std::uint16_t peer_port_ = 0;
    State state_ = State::handshake;
    std::uint8_t client_node_ = 0;  // 0 until the handshake succeeded
    // The timer fires at timer_at_ and then compares with deadline_, so moving the
    // deadline later (every request) costs no timer operation.
    Clock::time_point deadline_ = Clock::time_point::max();
    Deadline deadline_kind_ = Deadline::handshake;
    Clock::time_point timer_at_ = Clock::time_point::max();
    bool timer_armed_ = false;
    std::uint64_t timer_generation_ = 0;
    // The writer (issue 18 layout): one write on the wire at a time, so packets never
    // interleave, and what waits for it. The transitions, all of them:
    //   idle -> response      send_and_continue (a response or an error notice)
    //   idle -> confirmation  send_confirmation (command 6)
    //   idle -> late_frame    write_late (a deferred answer or a pushed frame)
    //   any  -> idle          that write's completion, which then calls write_next()
    // Asked to write while not idle: a response waits in deferred_, command 6 in
    // confirm_wanted_, a late frame in late_; write_next() starts them in that order.
    // Reading waits while a response is written (and resumes after it), so at most one
    // response is ever deferred.
    enum class Write : std::uint8_t { idle, response, confirmation, late_frame };
    struct DeferredResponse {
        std::size_t size = 0;
        bool close_after = false;
    };
    void start_write(Write what) noexcept;
    void write_next();
    Write write_ = Write::idle;
    bool confirm_wanted_ = false;
    std::optional<DeferredResponse> deferred_;
    bool logged_foreign_source_ = false;  // one warning per connection
    std::size_t drained_ = 0;
    std::size_t served_ = 0;  // packets answered by the last serve_buffered()
    static constexpr unsigned rounds_per_turn = 8;
    // Room for two maximal packets so a read never has to wait for the parser.
    std::array<std::uint8_t, 2 * tcp_max_packet> in_{};
    std::size_t in_size_ = 0;
    std::array<std::uint8_t, tcp_max_packet> out_{};
    std::size_t out_size_pending_ = 0;  // bytes of out_ to send after handle_packet
    std::array<std::uint8_t, tcp_header_size> confirmation_{};
    // Deferred answers and pushed frames with their envelope; bounded (every gateway
    // port's queue fits).
    static constexpr std::size_t max_late = 64;
    std::deque<std::vector<std::uint8_t>> late_;
    std::function<bool(Bytes)> response_hook_;
};

}  // namespace fins::server
