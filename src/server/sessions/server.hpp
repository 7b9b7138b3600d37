// finsd's network front: FINS/UDP and FINS/TCP on one port, glued to the pure
// Dispatcher. Everything runs on one asio::io_context thread, so the virtual PLC needs
// no locks and every request sees the effects of the one before it.
//
// UDP: one datagram is one FINS frame; the response goes to the datagram's source
//      address and port (what CS/CJ Ethernet units do with the dynamic conversion
//      method, frames section 2). Batched and non-blocking: see udp_session.hpp.
// TCP: the FINS/TCP envelope (frames section 3): node-address handshake with
//      auto-assignment, then FRAME SEND packets in both directions. Each response is
//      sent with one write; TCP_NODELAY keeps request/response traffic off delayed ACKs.
//      The handshake's node is the connection's identity (tcp_session.hpp); deadlines
//      and a cap on unfinished handshakes keep stalled peers from holding slots; a
//      failing accept (no descriptors left) backs off instead of spinning.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "fins/error.hpp"
#include "fins/frame.hpp"
#include "server/instructions/instruction_udp.hpp"
#include "server/sessions/tcp_client.hpp"
#include "server/sessions/tcp_limits.hpp"
#include "transport/asio.hpp"

namespace fins::plc {
class Plc;
}

namespace fins::server {

class Dispatcher;
class Router;
class SerialPorts;

struct ServerOptions {
    std::string bind_address = "127.0.0.1";
    std::uint16_t port = 9600;  // 0 picks a free port (tests)
    bool udp = true;
    bool tcp = true;
    // 0 = derive: last octet of the bound IPv4 address (loopback too), 1 on a wildcard.
    std::uint8_t node = 0;
    std::uint8_t network = 0;  // this node's FINS network address (00 = local network)
    // W596 1-2: up to 16 FINS/TCP connections.
    std::size_t max_tcp_connections = 16;
    // Deadlines, idle timeout, keep-alive, cap on unfinished handshakes (tcp_limits.hpp).
    TcpLimits tcp_limits;
    // Out of descriptors (or any other accept failure): retry after a back-off that
    // doubles up to this, logging at most once per accept_log_interval.
    std::chrono::milliseconds accept_retry_max{1'000};
    std::chrono::milliseconds accept_log_interval{10'000};
    // In a plant: the router and this server's port in it (router.hpp); null: one node.
    Router* router = nullptr;
    std::size_t router_port = 0;
    // PLC-initiated messages: where remote nodes are ([[remote]], instruction_udp.hpp);
    // those with `tcp` get a FINS/TCP client connection each (tcp_client.hpp), which
    // holds one of the max_tcp_connections slots.
    std::vector<RemoteNode> remotes;
    TcpClientTiming tcp_client_timing;
};

// One FINS/TCP client connection as finsd's web page lists it.
struct TcpConnectionInfo {
    std::string address;       // the peer's IP address
    bool established = false;  // false: in the handshake (or closing after a refusal)
    std::uint16_t port = 0;    // the peer's port
    std::uint8_t node = 0;     // the client node the handshake gave it (0: none yet)
};

// A FINS/UDP peer heard from lately (at most RecentPeers::capacity, newest first).
struct UdpPeerInfo {
    std::string address;  // the datagrams' source IP address
    std::uint16_t port = 0;
    std::uint8_t node = 0;  // SA1 of its last frame
    std::chrono::system_clock::time_point last_seen{};
};

// The node number finsd takes when none is given (see ServerOptions::node).
std::uint8_t derive_node(const std::string& bind_address) noexcept;

class Server {
  public:
    // Binds the sockets and starts accepting; the caller runs `io`.
    static Result<std::unique_ptr<Server>> start(asio::io_context& io, plc::Plc& plc,
                                                 const ServerOptions& options);
    ~Server();
    Server(const Server&) = delete;
    Server& operator=(const Server&) = delete;

    [[nodiscard]] std::uint16_t udp_port() const noexcept;
    [[nodiscard]] std::uint16_t tcp_port() const noexcept;
    [[nodiscard]] NodeAddress address() const noexcept;
    [[nodiscard]] std::size_t tcp_connections() const noexcept;
    // The FINS/TCP client connections open now, in accept order (allocates: for the page).
    [[nodiscard]] std::vector<TcpConnectionInfo> tcp_connection_list() const;
    // The FINS/UDP peers heard from lately, newest first (allocates: for the page).
    [[nodiscard]] std::vector<UdpPeerInfo> udp_peer_list() const;
    // The one dispatcher every session uses (serial sessions attach to it too).
    [[nodiscard]] Dispatcher& dispatcher() noexcept;
    // Sends `frame` as a datagram from the FINS/UDP socket (false: no UDP, or not sent).
    bool send_datagram(Bytes frame, const std::array<std::uint8_t, 4>& ip,
                       std::uint16_t port) noexcept;
    // Sends `frame` on the FINS/TCP connection holding client node `node` (false: none).
    bool send_to_tcp_node(std::uint8_t node, Bytes frame);
    // This node's Send/Rcv/SendCmd engine (network_instructions.hpp).
    NetworkInstructions& instructions() noexcept;
    // The FINS/TCP client connections, in [[remote]] order.
    [[nodiscard]] std::vector<const TcpClient*> tcp_clients() const;
    // Serves these Serial Gateway ports (W342 5-3-46 .. 5-3-48) from now on; they must
    // outlive the server's use of them.
    void attach_serial_ports(SerialPorts* ports) noexcept;

    // Closes the sockets and every TCP session; pending handlers finish on `io`.
    void stop();

    struct Impl;

  private:
    explicit Server(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace fins::server
