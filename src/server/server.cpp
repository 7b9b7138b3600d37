#include "server/server.hpp"

#include <array>
#include <list>

#include <spdlog/spdlog.h>
#include <asio/ip/tcp.hpp>
#include <asio/ip/udp.hpp>

#include "fins/node_address.hpp"
#include "server/dispatcher.hpp"
#include "server/tcp_session.hpp"

namespace fins::server {

std::uint8_t derive_node(const std::string& bind_address) noexcept {
    std::error_code ec;
    const auto ip = asio::ip::make_address(bind_address, ec);
    if (ec || ip.is_unspecified()) return 1;
    // The same rule as the client's default destination (fins/node_address.hpp).
    const auto node =
        ip.is_v4() ? node_from_ip(ip.to_v4().to_bytes()) : node_from_ip(ip.to_v6().to_bytes());
    // .0 and .255 are not host numbers; a FINS node must be 1-254.
    return (node == 0 || node == 255) ? 1 : node;
}

struct Server::Impl {
    Impl(asio::io_context& context, plc::Plc& plc, NodeAddress self, std::size_t max_connections)
        : dispatcher(plc, self),
          udp_socket(context),
          acceptor(context),
          nodes(self.node, max_connections) {}

    void receive_udp() {
        udp_socket.async_receive_from(
            asio::buffer(udp_in), udp_peer, [this](std::error_code ec, std::size_t n) {
                if (ec == asio::error::operation_aborted || !udp_socket.is_open()) return;
                if (!ec) {
                    const RequestContext context{Link::udp, std::chrono::system_clock::now()};
                    const std::size_t out =
                        dispatcher.handle(Bytes{udp_in.data(), n}, udp_out, context);
                    if (out > 0) {
                        std::error_code send_ec;
                        udp_socket.send_to(asio::buffer(udp_out.data(), out), udp_peer, 0, send_ec);
                        if (send_ec)
                            spdlog::warn("fins/udp: reply to {} failed: {}",
                                         udp_peer.address().to_string(), send_ec.message());
                    }
                } else {
                    // e.g. ICMP port unreachable from an earlier reply: keep serving.
                    spdlog::debug("fins/udp: receive: {}", ec.message());
                }
                receive_udp();
            });
    }

    void accept_tcp() {
        acceptor.async_accept([this](std::error_code ec, asio::ip::tcp::socket socket) {
            if (ec == asio::error::operation_aborted || !acceptor.is_open()) return;
            if (!ec) {
                sessions.remove_if([](const std::weak_ptr<TcpSession>& w) {
                    auto s = w.lock();
                    return !s || !s->open();
                });
                auto session = std::make_shared<TcpSession>(std::move(socket), dispatcher, nodes);
                sessions.push_back(session);
                session->start();
            } else {
                spdlog::warn("fins/tcp: accept failed: {}", ec.message());
            }
            accept_tcp();
        });
    }

    Dispatcher dispatcher;
    asio::ip::udp::socket udp_socket;
    asio::ip::udp::endpoint udp_peer;
    // A datagram one byte longer than the largest frame is still received whole, so the
    // dispatcher can answer 1001 instead of seeing a silently truncated frame.
    std::array<std::uint8_t, max_frame_size + 1> udp_in{};
    std::array<std::uint8_t, max_frame_size> udp_out{};
    asio::ip::tcp::acceptor acceptor;
    TcpNodeTable nodes;
    std::list<std::weak_ptr<TcpSession>> sessions;
};

Result<std::unique_ptr<Server>> Server::start(asio::io_context& io, plc::Plc& plc,
                                              const ServerOptions& options) {
    std::error_code ec;
    const auto ip = asio::ip::make_address(options.bind_address, ec);
    if (ec) return Unexpected(ec);
    const std::uint8_t node = options.node != 0 ? options.node : derive_node(options.bind_address);
    const NodeAddress self{options.network, node, cpu_unit};
    auto impl = std::make_unique<Impl>(io, plc, self, options.max_tcp_connections);

    std::uint16_t port = options.port;
    if (options.tcp) {
        const asio::ip::tcp::endpoint ep{ip, port};
        impl->acceptor.open(ep.protocol(), ec);
        if (!ec) impl->acceptor.set_option(asio::socket_base::reuse_address(true), ec);
        if (!ec) impl->acceptor.bind(ep, ec);
        if (!ec) impl->acceptor.listen(asio::socket_base::max_listen_connections, ec);
        if (ec) return Unexpected(ec);
        // With port 0 the UDP socket takes the same number TCP was given.
        port = impl->acceptor.local_endpoint().port();
    }
    if (options.udp) {
        const asio::ip::udp::endpoint ep{ip, port};
        impl->udp_socket.open(ep.protocol(), ec);
        if (!ec) impl->udp_socket.bind(ep, ec);
        if (ec) return Unexpected(ec);
    }
    if (options.tcp) impl->accept_tcp();
    if (options.udp) impl->receive_udp();
    return std::unique_ptr<Server>(new Server(std::move(impl)));
}

Server::Server(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Server::~Server() {
    stop();
}

std::uint16_t Server::udp_port() const noexcept {
    std::error_code ec;
    return impl_->udp_socket.is_open() ? impl_->udp_socket.local_endpoint(ec).port() : 0;
}

std::uint16_t Server::tcp_port() const noexcept {
    std::error_code ec;
    return impl_->acceptor.is_open() ? impl_->acceptor.local_endpoint(ec).port() : 0;
}

NodeAddress Server::address() const noexcept {
    return impl_->dispatcher.self();
}

std::size_t Server::tcp_connections() const noexcept {
    return impl_->nodes.in_use();
}

void Server::stop() {
    std::error_code ignored;
    impl_->udp_socket.close(ignored);
    impl_->acceptor.close(ignored);
    for (auto& weak : impl_->sessions)
        if (auto s = weak.lock()) s->close();
    impl_->sessions.clear();
}

}  // namespace fins::server
