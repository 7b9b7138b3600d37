// finsd's metrics, kept as plain integers where the events happen and written out in the
// Prometheus text exposition format (version 0.0.4) by expose(). No sockets: finsd's
// HTTP server (src/web/) serves the text on GET /metrics.
//
// Debian 12 has no prometheus-cpp package (docs/library.md "Dependencies"): this is the
// small part of it finsd needs. Counters are relaxed atomics in fixed tables (no
// allocation, no lock on the request path; test binaries run servers on several
// threads), keyed by a small integer the hook already has (command code, end code).
//
// The hooks are one line each at the place the event happens:
//   Dispatcher::handle          start_request()   (the time its answer is measured from)
//   Dispatcher::Reply::answer   note_request(command, end code)
//   UdpSession::note_dropped    note_datagrams_dropped(n)
//   Router::forward / relay_error   note_relay() / note_relay_error(end code)
//   NetworkInstructions::finish note_instruction(kind, completion code)
//   sessions/failure_boundary.cpp  note_request_failure() / note_control_failure()
// Gauges (connections by state, file memory bytes, serial ports) are read at scrape time
// by the caller and passed to expose().
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins::server::metrics {

// A counter family keyed by a 32-bit key: a fixed open-addressing table of atomics.
// Keys beyond its room are counted in overflow() (and exposed as key "other").
class KeyedCounter {
  public:
    static constexpr std::size_t slots = 1024;
    void add(std::uint32_t key, std::uint64_t n = 1) noexcept;
    [[nodiscard]] std::uint64_t value(std::uint32_t key) const noexcept;
    [[nodiscard]] std::uint64_t overflow() const noexcept {
        return overflow_.load(std::memory_order_relaxed);
    }
    // (key, count) of every key seen, in no particular order.
    void for_each(const std::function<void(std::uint32_t, std::uint64_t)>& f) const;

  private:
    std::array<std::atomic<std::uint32_t>, slots> keys_{};  // key + 1; 0: empty
    std::array<std::atomic<std::uint64_t>, slots> counts_{};
    std::atomic<std::uint64_t> overflow_{0};
};

// Request latency: cumulative buckets from 1 us to 100 ms (a FINS answer from the model
// takes microseconds; a file memory write with durability=power, milliseconds).
class Histogram {
  public:
    static constexpr std::array<double, 12> bounds{1e-6, 2.5e-6, 5e-6, 1e-5, 2.5e-5, 5e-5,
                                                   1e-4, 2.5e-4, 5e-4, 1e-3, 1e-2,   1e-1};
    void observe(std::chrono::nanoseconds d) noexcept;
    [[nodiscard]] std::uint64_t count() const noexcept {
        return count_.load(std::memory_order_relaxed);
    }
    [[nodiscard]] std::uint64_t bucket(std::size_t i) const noexcept {
        return buckets_[i].load(std::memory_order_relaxed);
    }
    [[nodiscard]] std::uint64_t sum_ns() const noexcept {
        return sum_ns_.load(std::memory_order_relaxed);
    }

  private:
    std::array<std::atomic<std::uint64_t>, bounds.size()> buckets_{};  // not cumulative
    std::atomic<std::uint64_t> count_{0};
    std::atomic<std::uint64_t> sum_ns_{0};
};

struct Metrics {
    // key: command code << 16 | end code (flag bits off), for the commands of
    // command_table() only: any other code a client sends is counted in other_requests,
    // so random command codes add no series (exposed as command="other").
    KeyedCounter requests;
    KeyedCounter other_requests;  // key: end code
    Histogram request_duration;
    std::atomic<std::uint64_t> datagrams_dropped{0};
    std::atomic<std::uint64_t> relays{0};
    KeyedCounter relay_errors;   // key: end code
    KeyedCounter instructions;   // key: kind << 16 | completion code (0000 done)
    KeyedCounter http_requests;  // key: HTTP status
    std::atomic<std::uint64_t> websocket_resyncs{0};
    // Requests whose handling threw (sessions/failure_boundary.hpp).
    std::atomic<std::uint64_t> request_failures{0};
    std::atomic<std::uint64_t> control_failures{0};
    // Exceptions the web server's failure boundary caught (src/web/, docs/web.md).
    std::atomic<std::uint64_t> web_handler_failures{0};
    // WebSocket connections closed for exceeding their message budget (1008).
    std::atomic<std::uint64_t> websocket_policy_closes{0};
};

// The process's metrics (every Server, Router and engine of a plant shares them).
Metrics& process_metrics() noexcept;

using Clock = std::chrono::steady_clock;
// The request being handled on this thread started now (a thread-local time point: a
// plant's router hands frames on down the call stack, the innermost one counts).
void start_request() noexcept;
void note_request(CommandCode command, EndCode code) noexcept;
void note_datagrams_dropped(std::uint64_t n) noexcept;
void note_relay() noexcept;
void note_relay_error(EndCode code) noexcept;
// kind: 0 send, 1 recv, 2 sendcmd (InstructionKind's order).
void note_instruction(std::uint8_t kind, std::uint16_t completion) noexcept;
void note_http_request(unsigned status) noexcept;
void note_websocket_resync() noexcept;
void note_request_failure() noexcept;
void note_control_failure() noexcept;
void note_web_handler_failure() noexcept;
void note_websocket_policy_close() noexcept;

// A gauge (or a counter the caller keeps) for expose(): one sample per label set.
struct Sample {
    std::string labels;  // e.g. state="open" (no braces); "" for none
    double value = 0;
};
struct Family {
    std::string name;
    std::string help;
    std::string type = "gauge";
    std::vector<Sample> samples;
};

// The text of GET /metrics: `m`, then `extra`.
std::string expose(const Metrics& m, std::span<const Family> extra = {});

}  // namespace fins::server::metrics
