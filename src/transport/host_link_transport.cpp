#include "transport/host_link_transport.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>

#include "transport/asio.hpp"

namespace fins::transport {
namespace {

// The direct form reaches only the directly connected CPU Unit's side: network and node
// bytes of both addresses 00.
HostLinkForm form_of(Bytes fins) noexcept {
    return fins[3] == 0 && fins[4] == 0 && fins[6] == 0 && fins[7] == 0 ? HostLinkForm::direct
                                                                        : HostLinkForm::network;
}

}  // namespace

HostLinkTransport::HostLinkTransport(asio::io_context& io, HostLinkOptions options)
    : io_(io), options_(std::move(options)), port_(io) {}

HostLinkTransport::~HostLinkTransport() {
    close();
}

void HostLinkTransport::async_open(OpenHandler done) {
    close();
    state_ = State::opening;
    const auto ec = port_.open(options_.line);
    Result<LinkInfo> result = LinkInfo{};  // nodes 0: the local network's own PLC
    if (ec) {
        close();
        result = Unexpected(ec);
    } else {
        state_ = State::open;
        receive();
    }
    // Handlers are never called from inside async_open().
    std::weak_ptr<int> life = life_;
    asio::post(io_, [life, done = std::move(done), result = std::move(result)]() mutable {
        if (!life.expired() && done) done(std::move(result));
    });
}

void HostLinkTransport::send(Bytes frame) {
    if (state_ != State::open || frame.size() < header_size + command_code_size) return;
    const auto n =
        encode_host_link_command(options_.unit, options_.wait, form_of(frame), frame, tx_);
    // The tracker refuses requests over the Host Link limit, so this only drops what
    // cannot be a Host Link frame at all.
    if (!n) return;
    queue_.push(Bytes{tx_.data(), *n});
    write_next();
}

void HostLinkTransport::write_next() {
    if (writing_ || queue_.empty()) return;
    writing_ = true;
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    asio::async_write(port_.port(), asio::buffer(queue_.front()),
                      [this, life, gen](boost::system::error_code ec, std::size_t) {
                          if (life.expired() || gen != generation_) return;
                          writing_ = false;
                          if (ec) return fail(make_error_code(ClientError::connection_closed));
                          queue_.pop();
                          write_next();
                      });
}

void HostLinkTransport::receive() {
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    // Room is always left: on_bytes() consumes or drops until less than a frame is held.
    port_.port().async_read_some(
        asio::buffer(rx_.data() + rx_size_, rx_.size() - rx_size_),
        [this, life, gen](boost::system::error_code ec, std::size_t n) {
            if (life.expired() || gen != generation_) return;
            if (ec) return fail(make_error_code(ClientError::connection_closed));
            on_bytes(n);
            if (!life.expired() && gen == generation_ && state_ == State::open) receive();
        });
}

void HostLinkTransport::on_bytes(std::size_t n) {
    rx_size_ += n;
    auto gen = generation_;
    std::weak_ptr<int> life = life_;
    std::size_t start = 0;
    while (start < rx_size_) {
        const auto s = scan_host_link(Bytes{rx_.data() + start, rx_size_ - start});
        if (s.status == HostLinkScan::Status::need_more) break;
        start += s.consumed;
        if (s.status == HostLinkScan::Status::frame) {
            on_frame(s.frame);
            if (life.expired() || gen != generation_) return;
        }
    }
    std::memmove(rx_.data(), rx_.data() + start, rx_size_ - start);
    rx_size_ -= start;
}

void HostLinkTransport::on_frame(Bytes frame) {
    auto decoded = decode_host_link(frame, true, fins_);
    if (!decoded) {
        // Another slave's garbled answer is none of our business.
        if (decoded.error().unit >= 0 && decoded.error().unit != options_.unit) return;
        if (decoded.error().unit < 0) return;  // no unit number: line noise
        if (on_error_) on_error_(make_error_code(decoded.error().error));
        return;
    }
    if (decoded->unit != options_.unit) return;
    if (decoded->end_code != HostLinkEndCode::normal) {
        if (on_error_) on_error_(make_error_code(decoded->end_code));
        return;
    }
    if (on_frame_) on_frame_(Bytes{fins_.data(), decoded->fins_size});
}

void HostLinkTransport::fail(boost::system::error_code reason) {
    close();
    if (on_close_) on_close_(reason);
}

void HostLinkTransport::close() {
    ++generation_;
    port_.close();
    queue_.clear();
    writing_ = false;
    rx_size_ = 0;
    state_ = State::closed;
}

}  // namespace fins::transport
