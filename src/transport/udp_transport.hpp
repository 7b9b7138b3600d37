// FINS/UDP client transport (frames section 2): one connected UDP socket to host:port,
// one datagram = one FINS frame. IPv4 and IPv6; the socket's family follows the first
// resolved address that can be connected.
//
// Connecting the socket makes the kernel drop datagrams from other peers. Errors the
// kernel reports on the socket after an ICMP message never close the transport (UDP has
// no connection): "port unreachable" (ECONNREFUSED) means nothing listens there now and
// goes to the error handler, so the client fails what waits instead of retrying into
// the void; "host/network unreachable" (often transient, e.g. ARP) is ignored: the
// attempt times out and is retried (W596 SendCmd, p. 3-16).
//
// The receive buffer (SO_RCVBUF) is sized for 256 answers in flight at once, each up to
// 2,012 bytes; the kernel caps it at net.core.rmem_max (Debian's default, 208 KiB, still
// holds 256 answers of up to about 400 bytes).
// Datagrams longer than 2,012 bytes are dropped. LinkInfo nodes come from
// node_from_address() of the local and the peer address.
//
// System calls (Linux): a readable socket is drained with recvmmsg, up to 16 datagrams a
// call, into buffers the thread's transports share (a drain hands every frame over before
// it returns; a drain that starts inside another one, from a handler that runs an
// io_context, uses the transport's own buffer). Frames sent by the frame handlers during
// a drain are held and leave together in one sendmmsg when the drain ends, in order,
// before the socket is watched again. Elsewhere one datagram per call.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "fins/frame.hpp"
#include "transport/asio.hpp"
#include "transport/socket_transport.hpp"

namespace fins::transport {

class UdpTransport final : public SocketTransport<asio::ip::udp> {
  public:
    UdpTransport(asio::io_context& io, TransportOptions options);
    ~UdpTransport() override;

    void async_open(OpenHandler done) override;
    void send(Bytes frame) override;
    void close() override;

    [[nodiscard]] bool peer_gone() override;
    [[nodiscard]] bool read_to_end_since_send() const noexcept override { return read_to_end_; }

  private:
    void connect_first(const asio::ip::udp::resolver::results_type& results);
    void finish_open(Result<LinkInfo> result) override;
    void receive();
    // Reads every datagram queued now and hands the frames over; false once the transport
    // was closed or replaced by a handler.
    bool drain();
    // Handles one receive result: a datagram, or an error (then `datagram` is empty);
    // false once the transport was closed or replaced.
    bool on_receive(boost::system::error_code ec, Bytes datagram);
    // Sends the frames held during a drain.
    void flush();
    void write_next();

    static constexpr std::size_t rx_size = max_frame_size + 1;  // a full one is too long
    std::array<std::uint8_t, rx_size> rx_{};
    bool holding_ = false;                 // inside a drain: send() holds frames
    std::vector<std::uint8_t> held_;       // frames held, back to back
    std::vector<std::size_t> held_sizes_;  // their sizes
    bool read_to_end_ = false;             // read_to_end_since_send(): Linux's drain only
};

// What a receive error on a connected UDP socket means.
enum class ReceiveError {
    nothing_listening,  // ICMP port unreachable: fail what waits, stay open
    transient,          // host/network unreachable and the like: ignore, keep receiving
    fatal,              // the socket itself is broken: close
};
ReceiveError classify_receive_error(boost::system::error_code ec) noexcept;

// SO_RCVBUF asked for: 256 answers of up to 2,012 bytes, at the ~4.5 KiB the kernel
// charges for each (the kernel doubles the value it is given).
inline constexpr int udp_receive_buffer = 256 * 4608 / 2;

}  // namespace fins::transport
