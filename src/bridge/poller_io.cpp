// PlcPoller's sockets: UDP (connected, one per PLC) or FINS/TCP (connect, the
// node-address handshake, length-prefixed frames). Answers go to on_frame(); a lost
// connection to go_offline().
#include "bridge/poller.hpp"

#include <cstring>

#include <fmt/format.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/write.hpp>

#include "fins/node_address.hpp"
#include "fins/tcp.hpp"

namespace fins::bridge {

void PlcPoller::close_socket() {
    ++socket_generation_;
    boost::system::error_code ignored;
    if (udp_.is_open()) udp_.close(ignored);
    if (tcp_.is_open()) tcp_.close(ignored);
    rx_used_ = 0;
    tx_.clear();
    writing_ = false;
}

void PlcPoller::open() {
    boost::system::error_code ec;
    if (plc_.transport == Transport::udp) {
        if (!udp_peer_) {
            asio::ip::udp::resolver resolver(io_);
            auto r = resolver.resolve(plc_.host, std::to_string(plc_.port), ec);
            if (ec || r.empty()) {
                go_offline(std::make_error_code(std::errc::host_unreachable));
                last_error_ = fmt::format("cannot resolve {}: {}", plc_.host, ec.message());
                return;
            }
            udp_peer_ = r.begin()->endpoint();
        }
        if (!udp_.is_open()) {
            udp_.open(udp_peer_->protocol(), ec);
            if (!ec) udp_.connect(*udp_peer_, ec);
            if (!ec) udp_.non_blocking(true, ec);
            if (ec) {
                close_socket();
                go_offline(std::make_error_code(std::errc::network_unreachable));
                return;
            }
            const auto local = udp_.local_endpoint(ec).address();
            const auto peer = udp_peer_->address();
            const auto bytes = [](const asio::ip::address& a) {
                std::vector<std::uint8_t> b;
                if (a.is_v4()) {
                    auto x = a.to_v4().to_bytes();
                    b.assign(x.begin(), x.end());
                } else {
                    auto x = a.to_v6().to_bytes();
                    b.assign(x.begin(), x.end());
                }
                return b;
            };
            destination_ = plc_.dest.value_or(NodeAddress{0, node_from_ip(bytes(peer)), 0});
            source_ = {0, node_from_ip(bytes(local)), 0};
            if (source_.node == destination_.node || source_.node == 0) source_.node = 254;
            udp_read();
        }
        return;
    }
    tcp_connect();
}

void PlcPoller::udp_read() {
    udp_.async_receive(asio::buffer(rx_), [this, gen = socket_generation_](
                                              boost::system::error_code ec, std::size_t n) {
        if (gen != socket_generation_ || ec == asio::error::operation_aborted) return;
        // connection_refused: an ICMP port unreachable for an earlier datagram (a stopped
        // PLC). The frame's timeout takes the PLC offline; keep listening.
        if (!ec) on_frame(Bytes(rx_.data(), n));
        udp_read();
    });
}

void PlcPoller::tcp_connect() {
    close_socket();
    state_ = state_ == State::online ? State::offline : state_;
    const auto gen = generation_;
    asio::ip::tcp::resolver resolver(io_);
    boost::system::error_code ec;
    auto r = resolver.resolve(plc_.host, std::to_string(plc_.port), ec);
    if (ec || r.empty()) {
        go_offline(std::make_error_code(std::errc::host_unreachable));
        return;
    }
    tcp_peer_ = r.begin()->endpoint();
    tcp_.async_connect(*tcp_peer_, [this, gen](boost::system::error_code e) {
        if (gen != generation_ || e == asio::error::operation_aborted) return;
        if (e) {
            go_offline(std::make_error_code(std::errc::connection_refused));
            return;
        }
        boost::system::error_code ignored;
        tcp_.set_option(asio::ip::tcp::no_delay(true), ignored);
        std::array<std::uint8_t, 20> hello{};
        ByteWriter w(hello);
        write_node_address_request(w, 0);  // 0: the server allocates our node
        tx_.insert(tx_.end(), hello.begin(), hello.end());
        tcp_flush();
        // The handshake must finish within the frame timeout.
        Request probe{Request::Kind::handshake};
        probe.service_id = 0;
        probe.deadline = PollClock::now() + plc_.timeout;
        probe.attempts = plc_.retries;  // no resend: the whole connection is retried
        window_.add(probe);
        arm_timeout();
        tcp_read();
    });
}

void PlcPoller::tcp_read() {
    tcp_.async_read_some(
        asio::buffer(rx_.data() + rx_used_, rx_.size() - rx_used_),
        [this, gen = generation_](boost::system::error_code ec, std::size_t n) {
            if (gen != generation_ || ec == asio::error::operation_aborted) return;
            if (ec) {
                go_offline(make_error_code(ClientError::connection_closed));
                return;
            }
            rx_used_ += n;
            std::size_t at = 0;
            while (true) {
                auto p = parse_tcp_frame(Bytes(rx_.data() + at, rx_used_ - at));
                if (p.status == TcpParse::Status::need_more) break;
                if (p.status == TcpParse::Status::error) {
                    go_offline(make_error_code(p.error));
                    return;
                }
                at += p.consumed;
                const auto command = static_cast<TcpCommand>(p.packet.command);
                if (p.packet.error != 0) {
                    go_offline(make_error_code(static_cast<TcpError>(p.packet.error)));
                    return;
                }
                if (command == TcpCommand::node_address_response) {
                    auto r = decode_node_address_response(p.packet.data);
                    if (!r) {
                        go_offline(make_error_code(ClientError::handshake_failed));
                        return;
                    }
                    source_ = {0, r->client_node, 0};
                    destination_ = plc_.dest.value_or(NodeAddress{0, r->server_node, 0});
                    window_.remove_handshake();
                    go_online();
                } else if (command == TcpCommand::frame) {
                    on_frame(p.packet.data);
                    if (gen != generation_ || !tcp_.is_open()) return;
                }
            }
            std::memmove(rx_.data(), rx_.data() + at, rx_used_ - at);
            rx_used_ -= at;
            tcp_read();
        });
}

void PlcPoller::tcp_flush() {
    if (writing_ || tx_.empty() || !tcp_.is_open()) return;
    std::swap(tx_, tx_busy_);
    tx_.clear();
    writing_ = true;
    asio::async_write(tcp_, asio::buffer(tx_busy_),
                      [this, gen = generation_](boost::system::error_code ec, std::size_t) {
                          if (gen != generation_ || ec == asio::error::operation_aborted) return;
                          writing_ = false;
                          tx_busy_.clear();
                          if (ec) {
                              go_offline(make_error_code(ClientError::connection_closed));
                              return;
                          }
                          tcp_flush();
                      });
}

}  // namespace fins::bridge
