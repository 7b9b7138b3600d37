// UdpInstructionTransport: the node's Send/Rcv/SendCmd frames over its UDP socket
// (instruction_udp.hpp).
#include "server/instructions/instruction_udp.hpp"

#include <spdlog/spdlog.h>

#include "server/sessions/tcp_client.hpp"
#include "server/sessions/udp_session.hpp"

namespace fins::server {

UdpInstructionTransport::UdpInstructionTransport(std::shared_ptr<UdpSession> udp,
                                                 asio::ip::address local, NodeAddress self,
                                                 std::vector<RemoteNode> remotes)
    : udp_(std::move(udp)), local_(std::move(local)), self_(self) {
    for (const auto& r : remotes) {
        if (r.tcp) continue;  // reached over its TCP client connection only
        boost::system::error_code ec;
        const auto ip = asio::ip::make_address(r.host, ec);
        if (ec) {
            // The config loader checked it; a bad entry here is a caller's bug.
            spdlog::warn("finsd: remote node {}.{}: bad address '{}'", r.network, r.node, r.host);
            continue;
        }
        remotes_.push_back({r.network, r.node, asio::ip::udp::endpoint{ip, r.port}});
    }
}

std::optional<asio::ip::udp::endpoint> UdpInstructionTransport::resolve(
    const NodeAddress& destination) const {
    const bool local = destination.network == local_network || destination.network == self_.network;
    const auto same_network = [&](std::uint8_t network) {
        return network == destination.network ||
               (local && (network == local_network || network == self_.network));
    };
    for (const auto& r : remotes_)
        if (r.node == destination.node && same_network(r.network)) return r.endpoint;
    if (!local || !udp_ || local_.is_unspecified()) return std::nullopt;
    // Node 00 is this PLC itself; FF the network's broadcast address.
    const std::uint8_t node = destination.node == 0 ? self_.node : destination.node;
    const std::uint16_t port = udp_->local_port();
    if (local_.is_v4()) {
        auto bytes = local_.to_v4().to_bytes();
        bytes.back() = node;
        return asio::ip::udp::endpoint{asio::ip::address_v4(bytes), port};
    }
    auto bytes = local_.to_v6().to_bytes();
    bytes.back() = node;
    return asio::ip::udp::endpoint{asio::ip::address_v6(bytes), port};
}

InstructionTransport::Sent UdpInstructionTransport::send_frame(const NodeAddress& destination,
                                                               Bytes frame,
                                                               InstructionRoute& route) {
    for (TcpClient* client : clients_) {
        if (!client->reaches(destination)) continue;
        if (!client->send_frame(frame)) return Sent::not_established;
        route = InstructionRoute{{}, client, client->client_node()};
        return Sent::ok;
    }
    const bool local = destination.network == local_network || destination.network == self_.network;
    if (local && tcp_route_ && destination.node != 0 && destination.node != broadcast_node) {
        if (const void* connection = tcp_route_(destination.node, frame)) {
            route = InstructionRoute{{}, connection, 0};
            return Sent::ok;
        }
    }
    if (!udp_ || !udp_->open()) return Sent::no_port;
    const auto to = resolve(destination);
    if (!to) return Sent::no_route;
    route = InstructionRoute{*to, nullptr, 0};
    return udp_->send_to(frame, to->data(), static_cast<socklen_t>(to->size())) ? Sent::ok
                                                                                : Sent::failed;
}

void UdpInstructionTransport::unanswered(const InstructionRoute& route) {
    for (TcpClient* client : clients_)
        if (static_cast<const void*>(client) == route.connection) client->note_unanswered();
}

}  // namespace fins::server
