#include "server/server.hpp"

#include <array>
#include <list>

#include <spdlog/spdlog.h>
#include <asio/ip/tcp.hpp>
#include <asio/ip/udp.hpp>

#include "server/dispatcher.hpp"
#include "server/tcp_session.hpp"
#include "server/udp_session.hpp"
#include "transport/transport.hpp"

namespace fins::server {

std::uint8_t derive_node(const std::string& bind_address) noexcept {
    std::error_code ec;
    const auto ip = asio::ip::make_address(bind_address, ec);
    if (ec || ip.is_unspecified()) return 1;
    const auto node = transport::node_from_address(ip);
    // .0 and .255 are not host numbers; a FINS node must be 1-254.
    return (node == 0 || node == 255) ? 1 : node;
}

struct Server::Impl {
    Impl(asio::io_context& context, plc::Plc& plc, NodeAddress self, std::size_t max_connections)
        : dispatcher(plc, self),
          acceptor(context),
          nodes(self.node, max_connections) {}

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
    std::shared_ptr<UdpSession> udp;  // null without FINS/UDP
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
        asio::ip::udp::socket socket{io};
        socket.open(ep.protocol(), ec);
        if (!ec) socket.bind(ep, ec);
        if (ec) return Unexpected(ec);
        impl->udp = std::make_shared<UdpSession>(std::move(socket), impl->dispatcher);
    }
    if (options.tcp) impl->accept_tcp();
    if (impl->udp) impl->udp->start();
    return std::unique_ptr<Server>(new Server(std::move(impl)));
}

Server::Server(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Server::~Server() {
    stop();
}

std::uint16_t Server::udp_port() const noexcept {
    return impl_->udp ? impl_->udp->local_port() : 0;
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
    if (impl_->udp) impl_->udp->close();
    impl_->acceptor.close(ignored);
    for (auto& weak : impl_->sessions)
        if (auto s = weak.lock()) s->close();
    impl_->sessions.clear();
}

}  // namespace fins::server
