#include "server/serial/serial_session.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

#include <spdlog/spdlog.h>
#include <boost/asio/write.hpp>

#include "server/dispatch/dispatcher.hpp"
#include "server/sessions/failure_boundary.hpp"
#include "transport/asio.hpp"
#include "transport/serial_options.hpp"

namespace fins::server {

SerialSession::SerialSession(asio::io_context& io, Dispatcher& dispatcher,
                             SerialSessionOptions options)
    : dispatcher_(dispatcher),
      options_(std::move(options)),
      port_(io),
      timer_(io),
      backoff_(options_.reopen_interval) {}

SerialSession::~SerialSession() {
    close();
}

bool SerialSession::start() {
    stopped_ = false;
    if (open()) return true;
    schedule_reopen();
    return false;
}

void SerialSession::close() {
    stopped_ = true;
    ++generation_;
    timer_.cancel();
    port_.close();
    busy_ = false;
    rx_size_ = 0;
}

bool SerialSession::open() {
    const auto ec = port_.open(options_.line);
    if (ec) {
        if (!failure_logged_)
            spdlog::warn("finsd: serial {} ({}): cannot open: {}; retrying", options_.name,
                         options_.line.device, ec.message());
        failure_logged_ = true;
        return false;
    }
    ++counters_.opens;
    if (failure_logged_)
        spdlog::warn("finsd: serial {} ({}): open again", options_.name, options_.line.device);
    else
        spdlog::info("finsd: serial {} on {}, Host Link unit {}", options_.name,
                     transport::describe_serial(options_.line), options_.unit);
    failure_logged_ = false;
    backoff_ = options_.reopen_interval;
    ++generation_;
    busy_ = false;
    rx_size_ = 0;
    receive();
    return true;
}

void SerialSession::lost(boost::system::error_code ec) {
    if (!failure_logged_)
        spdlog::warn("finsd: serial {} ({}): lost: {}; retrying", options_.name,
                     options_.line.device, ec.message());
    failure_logged_ = true;
    ++generation_;
    timer_.cancel();
    port_.close();
    busy_ = false;
    rx_size_ = 0;
    schedule_reopen();
}

void SerialSession::schedule_reopen() {
    if (stopped_) return;
    std::weak_ptr<SerialSession> weak = weak_from_this();
    const auto gen = generation_;
    timer_.expires_after(backoff_);
    timer_.async_wait([this, weak, gen](boost::system::error_code ec) {
        if (ec || weak.expired() || gen != generation_ || stopped_) return;
        if (open()) return;
        backoff_ = std::min(backoff_ * 2, options_.max_reopen_interval);
        schedule_reopen();
    });
}

void SerialSession::receive() {
    if (busy_ || !port_.is_open()) return;
    std::weak_ptr<SerialSession> weak = weak_from_this();
    const auto gen = generation_;
    // on_bytes() leaves less than max_line characters, so there is always room.
    port_.port().async_read_some(asio::buffer(rx_.data() + rx_size_, rx_.size() - rx_size_),
                                 [this, weak, gen](boost::system::error_code ec, std::size_t n) {
                                     if (weak.expired() || gen != generation_) return;
                                     if (ec) return lost(ec);
                                     on_bytes(n);
                                 });
}

void SerialSession::on_bytes(std::size_t n) {
    rx_size_ += n;
    std::size_t start = 0;
    while (!busy_ && start < rx_size_) {
        const auto s = scan_host_link(Bytes{rx_.data() + start, rx_size_ - start}, max_line);
        if (s.status == HostLinkScan::Status::need_more) break;
        start += s.consumed;
        if (s.status == HostLinkScan::Status::frame)
            on_frame(s.frame);
        else
            counters_.skipped += s.consumed;
    }
    std::memmove(rx_.data(), rx_.data() + start, rx_size_ - start);
    rx_size_ -= start;
    receive();
}

void SerialSession::on_frame(Bytes frame) {
    auto decoded = decode_host_link(frame, false, fins_in_);
    if (!decoded) {
        const auto& e = decoded.error();
        // Without a readable unit number nobody can tell whom it was for.
        if (e.unit < 0) {
            counters_.skipped += frame.size();
            return;
        }
        if (e.unit != options_.unit) {
            ++counters_.other_unit;
            return;
        }
        ++counters_.frames;
        ++counters_.errors;
        tx_size_ = encode_host_link_error(options_.unit, host_link_answer_for(e), tx_);
        return reply(tx_size_, 0);
    }
    if (decoded->unit != options_.unit) {
        ++counters_.other_unit;
        return;
    }
    ++counters_.frames;
    if (decoded->header_code != HostLinkHeaderCode::fa) {
        // "OF" frames answer commands a CPU Unit sends; finsd sends none.
        ++counters_.errors;
        tx_size_ =
            encode_host_link_error(options_.unit, HostLinkEndCode::command_not_supported, tx_);
        return reply(tx_size_, 0);
    }
    const RequestContext context{Link::serial, std::chrono::system_clock::now()};
    // The answer buffer holds Host Link's 538 data bytes: longer answers get 110B.
    const auto n = handle_guarded(dispatcher_, Bytes{fins_in_.data(), decoded->fins_size},
                                  fins_out_, context);
    if (n == 0) return;  // no-response bit, or nothing to answer
    auto size =
        encode_host_link_response(options_.unit, decoded->form, Bytes{fins_out_.data(), n}, tx_);
    if (!size) return;  // cannot happen: the dispatcher kept to the buffer
    ++counters_.answered;
    reply(*size, decoded->wait);
}

void SerialSession::reply(std::size_t size, std::uint8_t wait) {
    tx_size_ = size;
    busy_ = true;
    if (wait == 0) return write();
    // W342 3-5: the response wait time, in 10 ms units.
    std::weak_ptr<SerialSession> weak = weak_from_this();
    const auto gen = generation_;
    timer_.expires_after(std::chrono::milliseconds(10 * wait));
    timer_.async_wait([this, weak, gen](boost::system::error_code ec) {
        if (ec || weak.expired() || gen != generation_) return;
        write();
    });
}

void SerialSession::write() {
    std::weak_ptr<SerialSession> weak = weak_from_this();
    const auto gen = generation_;
    asio::async_write(port_.port(), asio::buffer(tx_.data(), tx_size_),
                      [this, weak, gen](boost::system::error_code ec, std::size_t) {
                          if (weak.expired() || gen != generation_) return;
                          if (ec) return lost(ec);
                          busy_ = false;
                          on_bytes(0);  // frames that arrived meanwhile, then read on
                      });
}

}  // namespace fins::server
