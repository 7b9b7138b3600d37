// TcpSession's lifetime: keep-alive, the deadlines and their one timer, and the close
// after an error notice (drain, then close). The request path is tcp_session.cpp.
#include <algorithm>
#include <cerrno>

#include <spdlog/spdlog.h>

#include "server/sessions/tcp_session.hpp"
#include "transport/socket_os.hpp"

namespace fins::server {

namespace {

// A refused peer may keep sending; past this many bytes it is closed without waiting.
constexpr std::size_t drain_limit = 256 * 1024;

}  // namespace

boost::system::error_code set_keepalive(asio::ip::tcp::socket& socket,
                                        std::chrono::seconds idle) noexcept {
    boost::system::error_code ec;
    socket.set_option(asio::socket_base::keep_alive(idle.count() > 0), ec);
    if (ec || idle.count() <= 0) return ec;
    transport::os::KeepAliveTiming timing;
    timing.idle = idle;
    timing.interval = std::max(std::chrono::seconds(1), idle / 3);
    timing.probes = 3;
    return transport::os::set_keepalive(socket.native_handle(), timing);
}

void TcpSession::close_after_notice() {
    // The node is free at once; only the socket lingers while it drains.
    nodes_.release(client_node_, this);
    client_node_ = 0;
    state_ = State::draining;
    boost::system::error_code ec;
    socket_.shutdown(asio::ip::tcp::socket::shutdown_send, ec);
    if (ec) {
        close();
        return;
    }
    set_deadline(Deadline::drain, limits_.drain_timeout);
    drained_ = 0;
    in_size_ = 0;
    drain();
}

void TcpSession::drain() {
    auto self = shared_from_this();
    socket_.async_read_some(asio::buffer(in_), [self](boost::system::error_code ec, std::size_t n) {
        if (self->state_ != State::draining) return;
        self->drained_ += n;
        // End of the peer's data (it read our notice and closed), an error, or too much.
        if (ec || self->drained_ > drain_limit) {
            self->close();
            return;
        }
        self->drain();
    });
}

void TcpSession::set_deadline(Deadline kind, Clock::duration after) {
    deadline_kind_ = kind;
    if (after <= Clock::duration::zero()) {
        deadline_ = Clock::time_point::max();  // idle_timeout 0: never
        return;
    }
    deadline_ = Clock::now() + after;
    if (!timer_armed_ || deadline_ < timer_at_) arm_timer(deadline_);
}

void TcpSession::arm_timer(Clock::time_point at) {
    timer_at_ = at;
    timer_armed_ = true;
    const auto generation = ++timer_generation_;
    timer_.expires_at(at);
    auto self = shared_from_this();
    timer_.async_wait([self, generation](boost::system::error_code) {
        // A newer arm or close() superseded this wait (its cancel may race the expiry).
        if (generation != self->timer_generation_) return;
        self->timer_armed_ = false;
        self->on_timer();
    });
}

void TcpSession::on_timer() {
    if (!open() || deadline_ == Clock::time_point::max()) return;
    if (Clock::now() < deadline_) {
        arm_timer(deadline_);
        return;
    }
    const char* what = deadline_kind_ == Deadline::handshake ? "handshake"
                       : deadline_kind_ == Deadline::frame   ? "frame"
                       : deadline_kind_ == Deadline::idle    ? "idle"
                                                             : "drain";
    log_summarised(nodes_.log().timeouts, spdlog::level::info, "fins/tcp: {}: {} timeout, closing",
                   peer_.to_string(), what);
    close();
}

}  // namespace fins::server
