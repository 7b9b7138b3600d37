// TcpClient: finsd's FINS/TCP client connections (tcp_client.hpp).
#include "server/sessions/tcp_client.hpp"

#include <algorithm>
#include <cstring>

#include <spdlog/spdlog.h>

#include "server/sessions/failure_boundary.hpp"

namespace fins::server {

namespace {

constexpr std::size_t destination_node_offset = 4;  // DA1
constexpr std::size_t source_node_offset = 7;       // SA1

transport::TransportOptions transport_options(const RemoteNode& remote,
                                              const TcpClientTiming& timing) {
    transport::TransportOptions o;
    o.host = remote.host;
    o.port = remote.port;
    o.open_timeout = timing.open_timeout;
    o.requested_node = remote.client_node;
    o.keepalive = timing.keepalive;
    return o;
}

}  // namespace

TcpClient::TcpClient(asio::io_context& io, Dispatcher& dispatcher, RemoteNode remote,
                     TcpClientTiming timing)
    : dispatcher_(dispatcher),
      remote_(std::move(remote)),
      self_(dispatcher.self()),
      timing_(timing),
      transport_(io, transport_options(remote_, timing_)),
      retry_timer_(io),
      random_(std::random_device{}()) {
    transport_.set_frame_handler([this](Bytes frame) { on_frame(frame); });
    transport_.set_close_handler([this](boost::system::error_code reason) { on_close(reason); });
}

TcpClient::~TcpClient() {
    stop();
}

void TcpClient::start() {
    running_ = true;
    open();
}

void TcpClient::stop() {
    running_ = false;
    *alive_ = false;
    alive_ = std::make_shared<bool>(true);
    retry_timer_.cancel();
    transport_.close();
    established_ = false;
    client_node_ = 0;
}

bool TcpClient::reaches(const NodeAddress& destination) const noexcept {
    const auto local = [&](std::uint8_t network) {
        return network == local_network || network == self_.network;
    };
    const bool network = destination.network == remote_.network ||
                         (local(destination.network) && local(remote_.network));
    return network && destination.node == remote_.node;
}

void TcpClient::open() {
    if (!running_) return;
    transport_.async_open([this, alive = std::weak_ptr<bool>(alive_)](auto link) {
        if (const auto a = alive.lock(); a && *a) on_open(std::move(link));
    });
}

void TcpClient::on_open(Result<transport::LinkInfo> link) {
    if (link && link->remote_node != remote_.node) {
        // Another node listens there: its answers would not be the remote's.
        transport_.close();
        ++counters_.failures;
        if (failures_in_row_ == 0)
            spdlog::warn("fins/tcp client: {}:{} is node {}, [[remote]] says node {}; retrying",
                         remote_.host, remote_.port, link->remote_node, remote_.node);
        return retry_later(next_delay());
    }
    if (!link) {
        ++counters_.failures;
        // One line per outage, not one per attempt.
        if (failures_in_row_ == 0)
            spdlog::warn(
                "fins/tcp client: node {} at {}:{}: {}; retrying with a back-off of up "
                "to {} ms",
                remote_.node, remote_.host, remote_.port, link.error().message(),
                timing_.retry_max.count());
        return retry_later(next_delay());
    }
    established_ = true;
    client_node_ = link->local_node;
    failures_in_row_ = 0;
    unanswered_in_row_ = 0;
    ++counters_.connects;
    spdlog::info("fins/tcp client: connected to node {} at {}:{} as node {}", remote_.node,
                 remote_.host, remote_.port, client_node_);
}

void TcpClient::on_close(boost::system::error_code reason) {
    spdlog::warn("fins/tcp client: connection to node {} at {}:{} lost: {}; reconnecting",
                 remote_.node, remote_.host, remote_.port, reason.message());
    drop();
}

void TcpClient::drop() {
    established_ = false;
    client_node_ = 0;
    ++counters_.drops;
    retry_later(std::chrono::milliseconds(timing_.retry_min));
}

void TcpClient::note_unanswered() {
    if (!established_ || timing_.max_unanswered == 0) return;
    if (++unanswered_in_row_ < timing_.max_unanswered) return;
    spdlog::warn(
        "fins/tcp client: node {} at {}:{} left {} frames in a row unanswered; "
        "reconnecting",
        remote_.node, remote_.host, remote_.port, unanswered_in_row_);
    ++counters_.silent;
    transport_.close();  // calls no handler
    drop();
}

std::chrono::milliseconds tcp_client_retry_delay(unsigned failures,
                                                 const TcpClientTiming& timing) noexcept {
    auto delay = timing.retry_min;
    // Doubling stops at retry_max: no overflow however long the outage.
    for (unsigned i = 0; i < failures && delay < timing.retry_max; ++i)
        delay *= 2;
    return std::min(delay, timing.retry_max);
}

std::chrono::milliseconds TcpClient::next_delay() noexcept {
    return tcp_client_retry_delay(failures_in_row_++, timing_);
}

void TcpClient::retry_later(std::chrono::milliseconds delay) {
    if (!running_) return;
    // Jitter: anywhere in [delay / 2, delay].
    const auto half = std::max<std::chrono::milliseconds::rep>(delay.count() / 2, 1);
    std::uniform_int_distribution<std::chrono::milliseconds::rep> pick(
        half, std::max(half, delay.count()));
    retry_timer_.expires_after(std::chrono::milliseconds(pick(random_)));
    retry_timer_.async_wait(
        [this, alive = std::weak_ptr<bool>(alive_)](boost::system::error_code ec) {
            const auto a = alive.lock();
            if (ec || !a || !*a) return;
            open();
        });
}

bool TcpClient::send_frame(Bytes frame) {
    if (!established_ || frame.size() < header_size || frame.size() > out_.size()) return false;
    std::memcpy(out_.data(), frame.data(), frame.size());
    out_[source_node_offset] = client_node_;
    transport_.send(Bytes{out_.data(), frame.size()});
    return true;
}

void TcpClient::on_frame(Bytes frame) {
    unanswered_in_row_ = 0;  // the server is alive
    if (frame.size() < header_size) {
        ++counters_.unmatched;
        return;
    }
    if ((frame[0] & icf_response) == 0) return serve(frame);
    // The connection's identity: its answers come from the node it was opened to.
    const bool from_remote = frame[source_node_offset] == remote_.node;
    if (!from_remote || !response_hook_ ||
        !take_response_guarded([&] { return response_hook_(frame, *this); }))
        ++counters_.unmatched;
}

void TcpClient::serve(Bytes command) {
    if (command.size() > request_.size()) return;
    // Our client node is this node's name on the connection: the dispatcher knows the
    // node by its own number, and the answer goes back under the client node.
    std::memcpy(request_.data(), command.data(), command.size());
    if (request_[destination_node_offset] == client_node_)
        request_[destination_node_offset] = self_.node;
    const RequestContext context{Link::tcp, std::chrono::system_clock::now(), nullptr};
    const std::size_t n = handle_guarded(dispatcher_, Bytes{request_.data(), command.size()},
                                         MutableBytes{out_.data(), out_.size()}, context);
    if (n == 0) return;
    if (out_[source_node_offset] == self_.node) out_[source_node_offset] = client_node_;
    ++counters_.served;
    transport_.send(Bytes{out_.data(), n});
}

}  // namespace fins::server
