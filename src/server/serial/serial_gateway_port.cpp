// SerialGatewayPort: one request at a time on the line (see serial_gateway_port.hpp).
#include "server/serial/serial_gateway_port.hpp"

#include <algorithm>

#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>
#include <boost/asio/write.hpp>

#include "fins/compoway_f.hpp"
#include "fins/modbus.hpp"
#include "transport/asio.hpp"

namespace fins::server {

namespace {

// Host Link frames end with '*' CR (W342 3-5; frames section 4).
constexpr std::array<std::uint8_t, 2> host_link_terminator{'*', '\r'};

}  // namespace

SerialGatewayPort::SerialGatewayPort(asio::io_context& io, GatewayPortConfig config)
    : io_(io), config_(std::move(config)), port_(io), timer_(io), silence_(io) {
    rx_.reserve(max_frame);
}

SerialGatewayPort::~SerialGatewayPort() = default;

boost::system::error_code SerialGatewayPort::open() {
    last_open_attempt_ = std::chrono::steady_clock::now();
    if (auto ec = port_.open(config_.line)) return ec;
    ++opened_;
    read_more();
    return {};
}

void SerialGatewayPort::close() {
    close_device();
    timer_.cancel();
    silence_.cancel();
    // Whatever waits is answered: nothing will go out on this port any more.
    while (!queue_.empty())
        finish(EndCode::response_timeout, {});
}

void SerialGatewayPort::submit(SerialFraming framing, Bytes frame, bool expect_answer,
                               SerialCompletion done, SerialAnswerCheck is_answer) {
    // One in progress plus max_queued waiting; a flood beyond gets 0204 at once.
    if (queue_.size() > max_queued || frame.size() > max_frame) {
        ++counters_.busy;
        done(EndCode::destination_node_busy, {});
        return;
    }
    queue_.push_back(Job{framing,
                         {frame.begin(), frame.end()},
                         expect_answer,
                         std::move(done),
                         std::move(is_answer)});
    if (!active_) start_next();
}

void SerialGatewayPort::start_next() {
    if (active_ || queue_.empty()) return;
    if (!port_.is_open()) {
        const auto now = std::chrono::steady_clock::now();
        if (now - last_open_attempt_ < reopen_interval || open()) {
            // The device is gone: a send-start timeout (W336 11-3-2), 0205.
            finish(EndCode::response_timeout, {});
            return;
        }
        spdlog::info("fins/serial: {}: {} reopened", config_.name, config_.line.device);
    }
    active_ = true;
    ++generation_;
    // W336 6-1-4: the reception buffer is cleared when the gateway runs.
    rx_.clear();
    auto self = shared_from_this();
    const Job& job = queue_.front();
    asio::async_write(port_.port(), asio::buffer(job.frame),
                      [self, generation = generation_](boost::system::error_code ec, std::size_t) {
                          self->on_written(generation, ec);
                      });
}

void SerialGatewayPort::on_written(std::uint64_t generation, boost::system::error_code ec) {
    // The write of a job that already finished (the port was closed or lost meanwhile):
    // it must not act on the job now active.
    if (!active_ || generation != generation_) return;
    if (ec) {
        lost(ec);
        return;
    }
    if (!queue_.front().expect_answer) {
        finish(EndCode::normal_completion, {});
        return;
    }
    // W336 6-6-2: the timeout runs from the end of sending until the answer.
    timer_.expires_after(config_.timeout);
    timer_.async_wait(
        [self = shared_from_this(), generation = generation_](boost::system::error_code e) {
            if (e || !self->active_ || generation != self->generation_) return;
            ++self->counters_.timeouts;
            spdlog::debug("fins/serial: {}: response timeout", self->config_.name);
            self->finish(EndCode::response_timeout, {});
        });
    try_answer();  // the answer may already be in
}

void SerialGatewayPort::close_device() {
    port_.close();
    // The read in progress on it ends (aborted) whenever its handler runs; a read on the
    // device opened next is another one.
    reading_ = false;
}

void SerialGatewayPort::read_more() {
    if (reading_ || !port_.is_open()) return;
    reading_ = true;
    port_.port().async_read_some(
        asio::buffer(read_buffer_),
        [self = shared_from_this(), opened = opened_](boost::system::error_code ec, std::size_t n) {
            // A read of a device closed since: the one open now has its own.
            if (opened != self->opened_) return;
            self->reading_ = false;
            self->on_read(ec, n);
        });
}

void SerialGatewayPort::on_read(boost::system::error_code ec, std::size_t n) {
    if (ec == asio::error::operation_aborted) return;
    if (ec) {
        lost(ec);
        return;
    }
    if (!active_ || !queue_.front().expect_answer) {
        counters_.late_bytes += n;  // late or unsolicited: discarded
    } else {
        const std::size_t room = max_frame - std::min(max_frame, rx_.size());
        rx_.insert(rx_.end(), read_buffer_.begin(),
                   read_buffer_.begin() + static_cast<std::ptrdiff_t>(std::min(n, room)));
        try_answer();
    }
    read_more();
}

bool SerialGatewayPort::try_answer() {
    if (!active_ || rx_.empty()) return false;
    const Bytes received{rx_.data(), rx_.size()};
    switch (queue_.front().framing) {
        case SerialFraming::compoway_f: {
            const auto parsed = compoway_f::parse_frame(received);
            using S = compoway_f::FrameParse::Status;
            if (parsed.status == S::need_more) break;
            if (parsed.status == S::complete) {
                finish(EndCode::normal_completion, parsed.body);
                return true;
            }
            ++counters_.bad_checksums;
            finish(EndCode::transmission_error, {});
            return true;
        }
        case SerialFraming::modbus_ascii: {
            const auto parsed = modbus::parse_ascii_frame(received);
            using S = modbus::AsciiParse::Status;
            if (parsed.status == S::need_more) break;
            if (parsed.status == S::complete) {
                finish(EndCode::normal_completion, parsed.ascii);
                return true;
            }
            ++counters_.bad_checksums;
            finish(EndCode::transmission_error, {});
            return true;
        }
        case SerialFraming::modbus_rtu: {
            const auto size = modbus::rtu_response_size(received);
            if (size && received.size() >= *size) {
                const Bytes frame = received.first(*size);
                if (modbus::rtu_crc_ok(frame)) {
                    finish(EndCode::normal_completion, frame.first(frame.size() - 2));
                } else {
                    ++counters_.bad_checksums;
                    finish(EndCode::transmission_error, {});
                }
                return true;
            }
            if (size) break;
            // Length unknown from the function code: 3.5 characters of silence end it.
            silence_.expires_after(rtu_silence());
            silence_.async_wait(
                [self = shared_from_this(), generation = generation_](boost::system::error_code e) {
                    if (e || !self->active_ || generation != self->generation_) return;
                    const Bytes frame{self->rx_.data(), self->rx_.size()};
                    if (modbus::rtu_crc_ok(frame)) {
                        self->finish(EndCode::normal_completion, frame.first(frame.size() - 2));
                    } else {
                        ++self->counters_.bad_checksums;
                        self->finish(EndCode::transmission_error, {});
                    }
                });
            break;
        }
        case SerialFraming::host_link: {
            // Whole frames up to '*' CR; the caller checks their FCS (0206 when wrong). A
            // frame the job's check refuses is dropped: the job keeps waiting.
            for (;;) {
                const auto end = std::search(rx_.begin(), rx_.end(), host_link_terminator.begin(),
                                             host_link_terminator.end());
                if (end == rx_.end()) break;
                const auto start = std::find(rx_.begin(), end, std::uint8_t{'@'});
                const auto size =
                    static_cast<std::size_t>(end - start) + host_link_terminator.size();
                const Bytes frame{rx_.data() + (start - rx_.begin()), size};
                const Job& job = queue_.front();
                if (!job.is_answer || job.is_answer(frame)) {
                    finish(EndCode::normal_completion, frame);
                    return true;
                }
                ++counters_.foreign_answers;
                spdlog::debug("fins/serial: {}: dropped an answer to another request",
                              config_.name);
                rx_.erase(rx_.begin(),
                          end + static_cast<std::ptrdiff_t>(host_link_terminator.size()));
            }
            break;
        }
    }
    if (rx_.size() >= max_frame) {
        ++counters_.bad_checksums;  // garbage that never ends as a frame
        finish(EndCode::transmission_error, {});
        return true;
    }
    return false;
}

void SerialGatewayPort::finish(EndCode code, Bytes payload) {
    if (queue_.empty()) return;
    Job job = std::move(queue_.front());
    queue_.pop_front();
    active_ = false;
    timer_.cancel();
    silence_.cancel();
    if (code == EndCode::normal_completion) ++counters_.answered;
    job.done(code, payload);
    rx_.clear();
    // The next request starts after this handler, so a completion that submits again
    // does not recurse without bound.
    if (!queue_.empty()) asio::post(io_, [self = shared_from_this()] { self->start_next(); });
}

void SerialGatewayPort::lost(const boost::system::error_code& ec) {
    spdlog::warn("fins/serial: {}: {}: {} (closed; each request tries to reopen it)", config_.name,
                 config_.line.device, ec.message());
    close_device();
    last_open_attempt_ = std::chrono::steady_clock::now();
    if (active_) finish(EndCode::response_timeout, {});
}

std::chrono::microseconds SerialGatewayPort::rtu_silence() const noexcept {
    // 11 bits per character; Modbus over Serial Line 2.5.1.1 fixes 1.75 ms above 19200.
    // A pseudo-terminal delivers in bursts, so never below 5 ms.
    const auto bits = config_.line.bits_per_character() * 35U / 10U;
    const auto micros = std::max<std::uint64_t>(
        5'000, std::uint64_t{bits} * 1'000'000U / std::max(config_.line.baud, 1U));
    return std::chrono::microseconds(micros);
}

}  // namespace fins::server
