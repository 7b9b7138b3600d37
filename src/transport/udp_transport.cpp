#include "transport/udp_transport.hpp"

#include <string>
#include <utility>

#include <asio/connect.hpp>

namespace fins::transport {

using asio::ip::udp;

UdpTransport::UdpTransport(asio::io_context& io, TransportOptions options)
    : options_(std::move(options)), resolver_(io), socket_(io), open_timer_(io) {}

UdpTransport::~UdpTransport() {
    close();
}

void UdpTransport::async_open(OpenHandler done) {
    close();
    state_ = State::opening;
    open_done_ = std::move(done);
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    open_timer_.expires_after(options_.open_timeout);
    open_timer_.async_wait([this, life, gen](std::error_code ec) {
        if (life.expired() || gen != generation_ || ec || state_ != State::opening) return;
        finish_open(Unexpected(make_error_code(ClientError::timeout)));
    });
    resolver_.async_resolve(options_.host, std::to_string(options_.port),
                            udp::resolver::numeric_service,
                            [this, life, gen](std::error_code ec, udp::resolver::results_type r) {
                                if (life.expired() || gen != generation_) return;
                                if (ec) return finish_open(Unexpected(ec));
                                connect_first(r);
                            });
}

void UdpTransport::connect_first(const udp::resolver::results_type& results) {
    std::error_code ec = asio::error::host_not_found;
    for (const auto& entry : results) {
        std::error_code ignored;
        socket_.close(ignored);
        ec.clear();
        socket_.open(entry.endpoint().protocol(), ec);
        if (!ec) socket_.connect(entry.endpoint(), ec);
        if (!ec) break;
    }
    if (!ec) socket_.non_blocking(true, ec);
    LinkInfo info;
    if (!ec) {
        auto local = socket_.local_endpoint(ec);
        auto remote = socket_.remote_endpoint(ec);
        if (!ec) {
            info.local_node = node_from_address(local.address());
            info.remote_node = node_from_address(remote.address());
        }
    }
    if (ec) return finish_open(Unexpected(ec));
    finish_open(info);
}

void UdpTransport::finish_open(Result<LinkInfo> result) {
    open_timer_.cancel();
    auto done = std::move(open_done_);
    open_done_ = nullptr;
    if (result) {
        state_ = State::open;
        receive();
    } else {
        close();
    }
    if (done) done(std::move(result));
}

void UdpTransport::receive() {
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    socket_.async_receive(asio::buffer(rx_), [this, life, gen](std::error_code ec, std::size_t n) {
        if (life.expired() || gen != generation_) return;
        if (ec == asio::error::connection_refused) return receive();  // ICMP: keep waiting
        if (ec) return fail(make_error_code(ClientError::connection_closed));
        // A datagram that fills the whole buffer is longer than 2,012 bytes: not FINS.
        if (n < rx_.size() && on_frame_) {
            on_frame_(Bytes{rx_.data(), n});
            if (life.expired() || gen != generation_) return;
        }
        receive();
    });
}

void UdpTransport::send(Bytes frame) {
    if (state_ != State::open) return;
    if (!writing_ && queue_.empty()) {
        std::error_code ec;
        socket_.send(asio::buffer(frame.data(), frame.size()), 0, ec);
        // Lost datagrams are the retry logic's business; only a full buffer is queued.
        if (ec != asio::error::would_block && ec != asio::error::try_again) return;
    }
    queue_.push(frame);
    write_next();
}

void UdpTransport::write_next() {
    if (writing_ || queue_.empty()) return;
    writing_ = true;
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    const auto& buffer = queue_.front();
    socket_.async_send(asio::buffer(buffer), [this, life, gen](std::error_code, std::size_t) {
        if (life.expired() || gen != generation_) return;
        writing_ = false;
        queue_.pop();
        write_next();
    });
}

void UdpTransport::fail(std::error_code reason) {
    close();
    if (on_close_) on_close_(reason);
}

void UdpTransport::close() {
    ++generation_;
    std::error_code ignored;
    resolver_.cancel();
    open_timer_.cancel();
    socket_.close(ignored);
    queue_.clear();
    writing_ = false;
    open_done_ = nullptr;
    state_ = State::closed;
}

}  // namespace fins::transport
