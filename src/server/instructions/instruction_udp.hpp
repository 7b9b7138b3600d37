// Where a node's Send/Rcv/SendCmd frames go over FINS/UDP: from the node's own UDP
// socket (its port, 9600 by default) to the remote node's IP address and port.
//
// First, a [[remote]] with transport = "tcp": the frame goes on this node's FINS/TCP
// client connection to it (tcp_client.hpp), or, while that is down, nowhere (W596 3:
// "FINS/TCP connection has not been established"; no fall back to FINS/UDP).
// Then FINS/TCP server side: a node of the local network that holds a FINS/TCP connection to this
// node (it is the client of that connection) gets the frame on it, and its answer comes
// back on it (W421 7-4 pairs each node with one connection; W596 3: with FINS/UDP off,
// the instructions need an established FINS/TCP connection). Otherwise FINS/UDP:
//
// The remote's address (W596 2-3, frames section 2 "IP <-> FINS node address"):
//   1. a [[remote]] entry for (network, node) of the config: its IP and port;
//   2. else, on the local network (network 00 or this node's), automatic generation:
//      this node's IP address with the last octet (IPv6: last byte) replaced by the node
//      number, and this node's own UDP port;
//   3. else none: the instruction ends with 0501 (no address for that network).
// A node bound to a wildcard address (0.0.0.0, ::) has no network prefix: only
// [[remote]] entries are reachable.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <boost/asio/ip/address.hpp>
#include <boost/asio/ip/udp.hpp>

#include "server/instructions/network_instructions.hpp"
#include "transport/asio.hpp"

namespace fins::server {

class UdpSession;

// A [[remote]] entry: the IP address and port of FINS node `node` on `network`
// (00 = the local network), reached over FINS/UDP, or over a FINS/TCP connection this
// node opens to it (tcp_client.hpp).
struct RemoteNode {
    std::uint8_t network = 0;
    std::uint8_t node = 0;
    std::string host;  // IPv4 or IPv6 text
    std::uint16_t port = 9600;
    bool tcp = false;              // transport = "tcp": a FINS/TCP client connection
    std::uint8_t client_node = 0;  // FINS/TCP: our node on it; 0 = the server allocates
};

class TcpClient;

class UdpInstructionTransport final : public InstructionTransport {
  public:
    // `udp` may be null (FINS/UDP off: every frame is Sent::no_port). `local` is the
    // bound address, `self` this node's FINS address.
    UdpInstructionTransport(std::shared_ptr<UdpSession> udp, asio::ip::address local,
                            NodeAddress self, std::vector<RemoteNode> remotes);
    Sent send_frame(const NodeAddress& destination, Bytes frame, InstructionRoute& route) override;
    // Tells the FINS/TCP client connection the frame went on, if any (tcp_client.hpp).
    void unanswered(const InstructionRoute& route) override;
    // Puts `frame` on the FINS/TCP connection of client node `node` and returns that
    // connection; null when no connection holds that node (or its queue is full). Set
    // by the server.
    using TcpRoute = std::function<const void*(std::uint8_t node, Bytes frame)>;
    void set_tcp_route(TcpRoute route) { tcp_route_ = std::move(route); }
    // This node's FINS/TCP client connections: a node one of them reaches gets its
    // frames on it, and only on it (Sent::not_established while it is down).
    void set_tcp_clients(std::vector<TcpClient*> clients) { clients_ = std::move(clients); }
    // The endpoint a frame for `destination` goes to, if any.
    [[nodiscard]] std::optional<asio::ip::udp::endpoint> resolve(
        const NodeAddress& destination) const;

  private:
    struct Remote {
        std::uint8_t network;
        std::uint8_t node;
        asio::ip::udp::endpoint endpoint;
    };
    std::shared_ptr<UdpSession> udp_;
    asio::ip::address local_;
    NodeAddress self_;
    std::vector<Remote> remotes_;
    TcpRoute tcp_route_;
    std::vector<TcpClient*> clients_;
};

}  // namespace fins::server
