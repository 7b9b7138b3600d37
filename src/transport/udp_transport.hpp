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
#pragma once

#include <array>
#include <cstdint>
#include <memory>

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

  private:
    void connect_first(const asio::ip::udp::resolver::results_type& results);
    void finish_open(Result<LinkInfo> result) override;
    void receive();
    // Handles one receive result; false once the transport was closed or replaced.
    bool on_receive(boost::system::error_code ec, std::size_t n);
    void write_next();

    std::array<std::uint8_t, max_frame_size + 1> rx_{};
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
