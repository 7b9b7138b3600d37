// Where a node's Send/Rcv/SendCmd frames go over FINS/UDP: from the node's own UDP
// socket (its port, 9600 by default) to the remote node's IP address and port.
//
// First, FINS/TCP: a node of the local network that holds a FINS/TCP connection to this
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

#include <asio/ip/address.hpp>
#include <asio/ip/udp.hpp>

#include "server/instructions/network_instructions.hpp"

namespace fins::server {

class UdpSession;

// A [[remote]] entry: the IP address and port of FINS node `node` on `network`
// (00 = the local network).
struct RemoteNode {
    std::uint8_t network = 0;
    std::uint8_t node = 0;
    std::string host;  // IPv4 or IPv6 text
    std::uint16_t port = 9600;
};

class UdpInstructionTransport final : public InstructionTransport {
  public:
    // `udp` may be null (FINS/UDP off: every frame is Sent::no_port). `local` is the
    // bound address, `self` this node's FINS address.
    UdpInstructionTransport(std::shared_ptr<UdpSession> udp, asio::ip::address local,
                            NodeAddress self, std::vector<RemoteNode> remotes);
    Sent send_frame(const NodeAddress& destination, Bytes frame) override;
    // Puts `frame` on the FINS/TCP connection of client node `node`; false when no
    // connection holds that node (or its queue is full). Set by the server.
    using TcpRoute = std::function<bool(std::uint8_t node, Bytes frame)>;
    void set_tcp_route(TcpRoute route) { tcp_route_ = std::move(route); }
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
};

}  // namespace fins::server
