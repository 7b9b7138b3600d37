// Client-side transports: move whole FINS frames between the client and one FINS node.
//
// A Transport is driven by the caller's asio::io_context on one thread (no locking).
// Life cycle: closed -> async_open() -> opening -> open -> (peer drop, envelope error,
// close()) -> closed -> async_open() again. Each open is a fresh connection (for TCP
// with a fresh node-address handshake).
//
// - send() takes one FINS frame (header ... data) and copies it: the bytes may be reused
//   as soon as send() returns. It first tries a non-blocking write, then queues what is
//   left; frames go out in order. Frames sent while not open are dropped (the client's
//   request tracker holds requests until the link is up).
// - The frame handler receives each complete FINS frame, once, in arrival order; the
//   view is valid only during the call.
// - The close handler is called once when an open transport fails or the peer closes it
//   (not for close(), and not for a failed open, which reports to the open handler).
// - The error handler hears errors after which the transport stays open (UDP: ICMP port
//   unreachable, "nothing listening" at the moment); what waits for an answer may fail.
// - Handlers may call send() and close(); after close() no handler of the old
//   connection is called again.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <system_error>

#include <boost/asio/ip/address.hpp>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "transport/asio.hpp"

namespace fins::transport {

// What the transport learned about the two ends when it opened.
struct LinkInfo {
    // TCP: the client node the server accepted or allocated (handshake command 1).
    // UDP: derived from the local address (node_from_address).
    std::uint8_t local_node = 0;
    // TCP: the server's node from the handshake. UDP: derived from the peer's address.
    std::uint8_t remote_node = 0;
};

struct TransportOptions {
    std::string host = "127.0.0.1";
    std::uint16_t port = 9600;
    // Bound on resolving, connecting and (TCP) the handshake; ClientError::timeout after.
    std::chrono::milliseconds open_timeout{2000};
    // TCP: the client node sent in the node-address request; 0 = ask the server to
    // allocate one (frames 3.2 command 0).
    std::uint8_t requested_node = 0;
    // TCP: keep-alive, so that a peer gone without a FIN or RST (power off, cable
    // pulled) ends the connection. idle > 0 turns it on: SO_KEEPALIVE with TCP_KEEPIDLE
    // = idle, TCP_KEEPINTVL = interval, TCP_KEEPCNT = count, and TCP_USER_TIMEOUT = idle
    // + interval x count (keep-alive probes only an idle connection; the user timeout
    // also ends one whose sent bytes stay unacknowledged). idle 0: the kernel's defaults.
    struct KeepAlive {
        std::chrono::seconds idle{0};
        std::chrono::seconds interval{0};
        int count = 0;
    };
    KeepAlive keepalive;
};

class Transport {
  public:
    enum class State { closed, opening, open };
    using OpenHandler = std::function<void(Result<LinkInfo>)>;
    using FrameHandler = std::function<void(Bytes frame)>;
    using CloseHandler = std::function<void(std::error_code reason)>;

    virtual ~Transport() = default;

    void set_frame_handler(FrameHandler h) { on_frame_ = std::move(h); }
    void set_close_handler(CloseHandler h) { on_close_ = std::move(h); }
    void set_error_handler(CloseHandler h) { on_error_ = std::move(h); }

    // Starts opening; requires State::closed. The handler gets the link info, or the
    // resolver/connect error, a TcpError from the handshake, or ClientError::timeout.
    virtual void async_open(OpenHandler done) = 0;
    virtual void send(Bytes frame) = 0;
    // Closes without calling any handler (an open in progress is abandoned silently).
    virtual void close() = 0;
    [[nodiscard]] virtual State state() const noexcept = 0;
    // True while queued bytes have not been handed to the kernel yet.
    [[nodiscard]] virtual bool write_pending() const noexcept = 0;
    // Looks at the socket without blocking and without calling any handler: true when
    // the peer has closed or reset an open connection (an end of stream waits unread).
    // UDP: clears an ICMP error left over from earlier traffic and returns false.
    [[nodiscard]] virtual bool peer_gone() = 0;
    // True when, since the last frame was sent, the receive side has read the socket to
    // its end (no datagram, no error left), so nothing an earlier answer left behind can
    // be waiting: a client whose io_context keeps running (an embedded one) then needs no
    // peer_gone() before its next request, since its loop reads an error as it comes.
    [[nodiscard]] virtual bool read_to_end_since_send() const noexcept { return false; }

  protected:
    FrameHandler on_frame_;
    CloseHandler on_close_;
    CloseHandler on_error_;
};

// fins::node_from_ip (fins/node_address.hpp, frames section 2) for an Asio address.
std::uint8_t node_from_address(const asio::ip::address& address) noexcept;

}  // namespace fins::transport
