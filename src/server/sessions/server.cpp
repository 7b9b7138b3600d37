#include "server/sessions/server.hpp"

#include "transport/socket_headers.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <list>
#include <optional>
#include <utility>

#include <spdlog/spdlog.h>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/steady_timer.hpp>

#include "fins/node_address.hpp"
#include "plc/plc.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/scenario/fault_hook.hpp"
#include "server/sessions/tcp_session.hpp"
#include "server/sessions/udp_session.hpp"
#include "transport/asio.hpp"

namespace fins::server {

std::uint8_t derive_node(const std::string& bind_address) noexcept {
    boost::system::error_code ec;
    const auto ip = asio::ip::make_address(bind_address, ec);
    if (ec || ip.is_unspecified()) return 1;
    // The same rule as the client's default destination (fins/node_address.hpp).
    const auto node =
        ip.is_v4() ? node_from_ip(ip.to_v4().to_bytes()) : node_from_ip(ip.to_v6().to_bytes());
    // .0 and .255 are not host numbers; a FINS node must be 1-254.
    return (node == 0 || node == 255) ? 1 : node;
}

struct Server::Impl {
    Impl(asio::io_context& context, plc::Plc& plc, NodeAddress self, const ServerOptions& options)
        : dispatcher(plc, self),
          acceptor(context),
          nodes(self.node, options.max_tcp_connections),
          limits(options.tcp_limits),
          accept_retry_max(options.accept_retry_max),
          accept_log_interval(options.accept_log_interval),
          accept_timer(context) {
        if (options.router != nullptr) dispatcher.attach(*options.router, options.router_port);
    }

    void accept_tcp() {
        acceptor.async_accept([this](boost::system::error_code ec, asio::ip::tcp::socket socket) {
            if (ec == asio::error::operation_aborted || !acceptor.is_open()) return;
            if (ec == asio::error::connection_aborted) {
                // The peer gave up while queued: nothing is wrong with us.
                accept_tcp();
                return;
            }
            if (ec) {
                accept_failed(ec);
                return;
            }
            if (accept_failures > 0) {
                if (accept_episode_logged)
                    spdlog::warn("fins/tcp: accepting again after {} failed attempts",
                                 accept_failures);
                accept_failures = 0;
                accept_episode_logged = false;
                accept_delay = std::chrono::milliseconds(0);
            }
            // A scenario's "node offline" (server/scenario/fault_hook.hpp): refused.
            if (dispatcher.faults() != nullptr && dispatcher.faults()->offline()) {
                boost::system::error_code ignored;
                socket.close(ignored);
                accept_tcp();
                return;
            }
            sessions.remove_if([](const std::weak_ptr<TcpSession>& w) {
                auto s = w.lock();
                return !s || !s->open();
            });
            evict_oldest_pending();
            auto session =
                std::make_shared<TcpSession>(std::move(socket), dispatcher, nodes, limits);
            // The session checked the answer's source is its client node; the route
            // checks it came on the connection the command went on.
            session->set_response_hook(
                [engine = instructions.get(), connection = session.get()](Bytes frame) {
                    return engine->on_response(frame, InstructionRoute{{}, connection, 0});
                });
            sessions.push_back(session);
            session->start();
            accept_tcp();
        });
    }

    // At the cap of connections without a finished handshake, the oldest one goes: a
    // real client finishes its handshake within a round trip, so the oldest is the one
    // most likely stalled, and a flood of new sockets cannot keep every slot.
    void evict_oldest_pending() {
        std::size_t pending = 0;
        for (const auto& weak : sessions)
            if (auto s = weak.lock(); s && s->pending()) ++pending;
        if (pending < limits.max_pending) return;
        for (const auto& weak : sessions)
            if (auto s = weak.lock(); s && s->pending()) {
                log_summarised(nodes.log().evictions, spdlog::level::info,
                               "fins/tcp: {} connections without a handshake, closing the oldest",
                               pending);
                s->close();
                return;
            }
    }

    // EMFILE/ENFILE and the like leave the connection queued, so an immediate retry
    // fails again at once (a busy loop writing a log line each time). Back off instead,
    // doubling up to accept_retry_max; UDP and open connections are served meanwhile,
    // and accepting resumes by itself. At most one failure line per accept_log_interval
    // (a failure that flaps with short recoveries included); the recovery of a logged
    // failure is logged once.
    void accept_failed(boost::system::error_code ec) {
        const auto now = std::chrono::steady_clock::now();
        const bool new_episode = accept_failures++ == 0;
        ++accept_unreported;
        if (!accept_logged || now - *accept_logged >= accept_log_interval) {
            if (new_episode)
                spdlog::warn("fins/tcp: accept failed: {}; retrying with a back-off of up to {} ms",
                             ec.message(), accept_retry_max.count());
            else
                spdlog::warn(
                    "fins/tcp: accept still failing: {} ({} failures since the last "
                    "report)",
                    ec.message(), accept_unreported);
            accept_logged = now;
            accept_unreported = 0;
            accept_episode_logged = true;
        }
        accept_delay =
            std::clamp(accept_delay * 2, std::chrono::milliseconds(10), accept_retry_max);
        accept_timer.expires_after(accept_delay);
        accept_timer.async_wait([this](boost::system::error_code timer_ec) {
            if (timer_ec || !acceptor.is_open()) return;
            accept_tcp();
        });
    }

    // The frame on the FINS/TCP connection that holds client node `node`, if one does:
    // that connection, or null.
    const TcpSession* push_to_tcp_node(std::uint8_t node, Bytes frame) {
        TcpSession* session = nodes.owner(node);
        return session != nullptr && session->push_frame(frame) ? session : nullptr;
    }

    Dispatcher dispatcher;
    std::shared_ptr<UdpSession> udp;  // null without FINS/UDP
    // PLC-initiated messages: answers arriving at the UDP session go to `instructions`.
    std::unique_ptr<UdpInstructionTransport> transport;
    std::unique_ptr<NetworkInstructions> instructions;
    std::vector<std::unique_ptr<TcpClient>> clients;  // [[remote]] transport = "tcp"
    asio::ip::tcp::acceptor acceptor;
    TcpNodeTable nodes;
    TcpLimits limits;
    std::list<std::weak_ptr<TcpSession>> sessions;  // in accept order
    std::chrono::milliseconds accept_retry_max;
    std::chrono::milliseconds accept_log_interval;
    asio::steady_timer accept_timer;
    std::chrono::milliseconds accept_delay{0};
    std::size_t accept_failures = 0;    // since the last successful accept
    std::size_t accept_unreported = 0;  // failures not yet counted in a log line
    bool accept_episode_logged = false;
    std::optional<std::chrono::steady_clock::time_point> accept_logged;
};

namespace {

// The TCP listener (into `acceptor`) and the UDP socket on one port number. With port 0 one
// of them takes a free number and the other the same one; that number can be taken for the
// other protocol (any client socket's ephemeral port comes from the same range), so a pair
// is looked for again, a bounded number of times, before "address in use" is the answer.
// The attempts alternate which protocol draws the number: Linux draws TCP listeners' from
// half the range only (odd numbers), UDP's from all of it.
bool bind_tcp(asio::ip::tcp::acceptor& acceptor, const asio::ip::address& ip, std::uint16_t& port,
              boost::system::error_code& ec) {
    boost::system::error_code ignored;
    acceptor.close(ignored);
    const asio::ip::tcp::endpoint ep{ip, port};
    acceptor.open(ep.protocol(), ec);
    if (!ec) acceptor.set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) acceptor.bind(ep, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (!ec) port = acceptor.local_endpoint(ec).port();
    return !ec;
}

bool bind_udp(asio::ip::udp::socket& socket, const asio::ip::address& ip, std::uint16_t& port,
              boost::system::error_code& ec) {
    boost::system::error_code ignored;
    socket.close(ignored);
    const asio::ip::udp::endpoint ep{ip, port};
    socket.open(ep.protocol(), ec);
    if (!ec) socket.bind(ep, ec);
    if (!ec) port = socket.local_endpoint(ec).port();
    return !ec;
}

std::optional<asio::ip::udp::socket> bind_listeners(asio::io_context& io,
                                                    const asio::ip::address& ip,
                                                    const ServerOptions& options,
                                                    asio::ip::tcp::acceptor& acceptor,
                                                    boost::system::error_code& ec) {
    asio::ip::udp::socket udp{io};
    if (!options.tcp || !options.udp) {
        std::uint16_t port = options.port;
        if (options.tcp) bind_tcp(acceptor, ip, port, ec);
        if (options.udp && bind_udp(udp, ip, port, ec)) return udp;
        return std::nullopt;
    }
    const int attempts = options.port == 0 ? 64 : 1;
    for (int attempt = 0; attempt < attempts; ++attempt) {
        std::uint16_t port = options.port;
        const bool udp_first = attempt % 2 == 1;
        const bool both = udp_first
                              ? bind_udp(udp, ip, port, ec) && bind_tcp(acceptor, ip, port, ec)
                              : bind_tcp(acceptor, ip, port, ec) && bind_udp(udp, ip, port, ec);
        if (both) return udp;
        if (ec != asio::error::address_in_use) break;
    }
    boost::system::error_code ignored;
    acceptor.close(ignored);
    return std::nullopt;
}

}  // namespace

Result<std::unique_ptr<Server>> Server::start(asio::io_context& io, plc::Plc& plc,
                                              const ServerOptions& options) {
    boost::system::error_code ec;
    const auto ip = asio::ip::make_address(options.bind_address, ec);
    if (ec) return Unexpected(ec);
    const std::uint8_t node = options.node != 0 ? options.node : derive_node(options.bind_address);
    const NodeAddress self{options.network, node, cpu_unit};
    auto impl = std::make_unique<Impl>(io, plc, self, options);
    // The CPU Unit is on from here: its scan cycle runs whether anyone asks or not.
    plc.power_on(std::chrono::system_clock::now());

    auto udp = bind_listeners(io, ip, options, impl->acceptor, ec);
    if (ec) return Unexpected(ec);
    if (udp) impl->udp = std::make_shared<UdpSession>(std::move(*udp), impl->dispatcher);
    impl->transport =
        std::make_unique<UdpInstructionTransport>(impl->udp, ip, self, options.remotes);
    impl->transport->set_tcp_route([raw = impl.get()](std::uint8_t client, Bytes frame) {
        return raw->push_to_tcp_node(client, frame);
    });
    impl->instructions =
        std::make_unique<NetworkInstructions>(io.get_executor(), plc, self, *impl->transport);
    std::vector<TcpClient*> clients;
    for (const auto& remote : options.remotes) {
        if (!remote.tcp) continue;
        auto& client = impl->clients.emplace_back(
            std::make_unique<TcpClient>(io, impl->dispatcher, remote, options.tcp_client_timing));
        // The answer's source node was checked against the connection's remote node;
        // the route checks it came on the connection the command went on.
        client->set_response_hook(
            [engine = impl->instructions.get()](Bytes frame, const TcpClient& connection) {
                return engine->on_response(
                    frame, InstructionRoute{{}, &connection, connection.client_node()});
            });
        clients.push_back(client.get());
    }
    impl->nodes.reserve_for_clients(clients.size());
    impl->transport->set_tcp_clients(clients);
    if (impl->udp)
        impl->udp->set_response_hook(
            [engine = impl->instructions.get()](Bytes frame, const sockaddr* peer, socklen_t size) {
                InstructionRoute from;
                // socklen_t: unsigned on Linux, int on Windows.
                if (std::cmp_less(size, 0) || std::cmp_greater(size, from.udp.capacity()))
                    return false;
                const auto bytes = static_cast<std::size_t>(size);
                std::memcpy(from.udp.data(), peer, bytes);
                from.udp.resize(bytes);
                return engine->on_response(frame, from);
            });
    if (options.tcp) impl->accept_tcp();
    for (auto& client : impl->clients)
        client->start();
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
    boost::system::error_code ec;
    return impl_->acceptor.is_open() ? impl_->acceptor.local_endpoint(ec).port() : 0;
}

NodeAddress Server::address() const noexcept {
    return impl_->dispatcher.self();
}

void Server::attach_serial_ports(SerialPorts* ports) noexcept {
    impl_->dispatcher.attach_serial_ports(ports);
}

Dispatcher& Server::dispatcher() noexcept {
    return impl_->dispatcher;
}

bool Server::send_datagram(Bytes frame, const std::array<std::uint8_t, 4>& ip,
                           std::uint16_t port) noexcept {
    if (!impl_->udp) return false;
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(port);
    std::memcpy(&to.sin_addr.s_addr, ip.data(), ip.size());
    return impl_->udp->send_to(frame, to);
}

bool Server::send_to_tcp_node(std::uint8_t node, Bytes frame) {
    return impl_->push_to_tcp_node(node, frame) != nullptr;
}

std::size_t Server::tcp_connections() const noexcept {
    return impl_->nodes.in_use();
}

std::vector<TcpConnectionInfo> Server::tcp_connection_list() const {
    std::vector<TcpConnectionInfo> out;
    for (const auto& weak : impl_->sessions)
        if (const auto s = weak.lock(); s != nullptr && s->open())
            out.push_back(
                {s->peer_address().to_string(), !s->pending(), s->peer_port(), s->client_node()});
    return out;
}

std::vector<UdpPeerInfo> Server::udp_peer_list() const {
    std::vector<UdpPeerInfo> out;
    if (impl_->udp == nullptr) return out;
    for (const auto& p : impl_->udp->recent_peers().peers()) {
        if (!p.used) continue;
        UdpPeerInfo info;
        info.node = p.node;
        info.last_seen = p.last_seen;
        char text[INET6_ADDRSTRLEN] = {};
        if (p.address.ss_family == AF_INET) {
            const auto& a = reinterpret_cast<const sockaddr_in&>(p.address);
            ::inet_ntop(AF_INET, &a.sin_addr, text, sizeof text);
            info.port = ntohs(a.sin_port);
        } else if (p.address.ss_family == AF_INET6) {
            const auto& a = reinterpret_cast<const sockaddr_in6&>(p.address);
            ::inet_ntop(AF_INET6, &a.sin6_addr, text, sizeof text);
            info.port = ntohs(a.sin6_port);
        }
        info.address = text;
        out.push_back(std::move(info));
    }
    std::sort(out.begin(), out.end(),
              [](const auto& a, const auto& b) { return a.last_seen > b.last_seen; });
    return out;
}

NetworkInstructions& Server::instructions() noexcept {
    return *impl_->instructions;
}

std::vector<const TcpClient*> Server::tcp_clients() const {
    std::vector<const TcpClient*> out;
    for (const auto& c : impl_->clients)
        out.push_back(c.get());
    return out;
}

void Server::stop() {
    boost::system::error_code ignored;
    impl_->instructions->stop();
    for (auto& client : impl_->clients)
        client->stop();
    if (impl_->udp) impl_->udp->close();
    impl_->acceptor.close(ignored);
    impl_->accept_timer.cancel();
    for (auto& weak : impl_->sessions)
        if (auto s = weak.lock()) s->close();
    impl_->sessions.clear();
}

}  // namespace fins::server
