// finsd's metrics and their exposition (contract in metrics.hpp).
#include "server/metrics/metrics.hpp"

#include <fmt/core.h>

#include "fins/command_table.hpp"

namespace fins::server::metrics {

namespace {

std::size_t slot_of(std::uint32_t key) noexcept {
    // Fibonacci hashing: command/end-code keys differ in few bits.
    return static_cast<std::size_t>((key * 2654435769u) >> 22) % KeyedCounter::slots;
}

constexpr const char* instruction_names[] = {"send", "recv", "sendcmd"};

void header(std::string& out, std::string_view name, std::string_view help, std::string_view type) {
    fmt::format_to(std::back_inserter(out), "# HELP {} {}\n# TYPE {} {}\n", name, help, name, type);
}

std::string number(double v) {
    return fmt::format("{}", v);
}

}  // namespace

void KeyedCounter::add(std::uint32_t key, std::uint64_t n) noexcept {
    const std::uint32_t stored = key + 1;
    std::size_t i = slot_of(key);
    for (std::size_t probes = 0; probes < slots; ++probes, i = (i + 1) % slots) {
        std::uint32_t k = keys_[i].load(std::memory_order_relaxed);
        if (k == 0) {
            std::uint32_t empty = 0;
            if (keys_[i].compare_exchange_strong(empty, stored, std::memory_order_relaxed))
                k = stored;
            else
                k = empty;
        }
        if (k == stored) {
            counts_[i].fetch_add(n, std::memory_order_relaxed);
            return;
        }
    }
    overflow_.fetch_add(n, std::memory_order_relaxed);
}

std::uint64_t KeyedCounter::value(std::uint32_t key) const noexcept {
    const std::uint32_t stored = key + 1;
    std::size_t i = slot_of(key);
    for (std::size_t probes = 0; probes < slots; ++probes, i = (i + 1) % slots) {
        const auto k = keys_[i].load(std::memory_order_relaxed);
        if (k == 0) return 0;
        if (k == stored) return counts_[i].load(std::memory_order_relaxed);
    }
    return 0;
}

void KeyedCounter::for_each(const std::function<void(std::uint32_t, std::uint64_t)>& f) const {
    for (std::size_t i = 0; i < slots; ++i)
        if (const auto k = keys_[i].load(std::memory_order_relaxed); k != 0)
            f(k - 1, counts_[i].load(std::memory_order_relaxed));
}

void Histogram::observe(std::chrono::nanoseconds d) noexcept {
    const auto ns = static_cast<std::uint64_t>(std::max<std::int64_t>(d.count(), 0));
    const double seconds = static_cast<double>(ns) * 1e-9;
    for (std::size_t i = 0; i < bounds.size(); ++i)
        if (seconds <= bounds[i]) {
            buckets_[i].fetch_add(1, std::memory_order_relaxed);
            break;
        }
    count_.fetch_add(1, std::memory_order_relaxed);
    sum_ns_.fetch_add(ns, std::memory_order_relaxed);
}

Metrics& process_metrics() noexcept {
    static Metrics metrics;
    return metrics;
}

namespace {
thread_local Clock::time_point request_started;
}  // namespace

void start_request() noexcept {
    request_started = Clock::now();
}

void note_request(CommandCode command, EndCode code) noexcept {
    auto& m = process_metrics();
    const auto started = request_started;
    if (find_command(command) != nullptr)
        m.requests.add(std::uint32_t{command.value()} << 16 | static_cast<std::uint16_t>(code));
    else
        m.other_requests.add(static_cast<std::uint16_t>(code));
    m.request_duration.observe(Clock::now() - started);
}

void note_datagrams_dropped(std::uint64_t n) noexcept {
    process_metrics().datagrams_dropped.fetch_add(n, std::memory_order_relaxed);
}

void note_relay() noexcept {
    process_metrics().relays.fetch_add(1, std::memory_order_relaxed);
}

void note_relay_error(EndCode code) noexcept {
    process_metrics().relay_errors.add(static_cast<std::uint16_t>(code));
}

void note_instruction(std::uint8_t kind, std::uint16_t completion) noexcept {
    process_metrics().instructions.add(std::uint32_t{kind} << 16 | completion);
}

void note_http_request(unsigned status) noexcept {
    process_metrics().http_requests.add(status);
}

void note_websocket_resync() noexcept {
    process_metrics().websocket_resyncs.fetch_add(1, std::memory_order_relaxed);
}

void note_request_failure() noexcept {
    process_metrics().request_failures.fetch_add(1, std::memory_order_relaxed);
}

void note_control_failure() noexcept {
    process_metrics().control_failures.fetch_add(1, std::memory_order_relaxed);
}

void note_web_handler_failure() noexcept {
    process_metrics().web_handler_failures.fetch_add(1, std::memory_order_relaxed);
}

void note_websocket_policy_close() noexcept {
    process_metrics().websocket_policy_closes.fetch_add(1, std::memory_order_relaxed);
}

std::string expose(const Metrics& m, std::span<const Family> extra) {
    std::string out;
    out.reserve(8192);
    const auto line = [&](std::string_view name, std::string_view labels, auto value) {
        if (labels.empty())
            fmt::format_to(std::back_inserter(out), "{} {}\n", name, value);
        else
            fmt::format_to(std::back_inserter(out), "{}{{{}}} {}\n", name, labels, value);
    };

    header(out, "fins_requests_total", "FINS requests answered by command and end code", "counter");
    m.requests.for_each([&](std::uint32_t key, std::uint64_t n) {
        line("fins_requests_total",
             fmt::format("command=\"{:04X}\",end_code=\"{:04X}\"", key >> 16, key & 0xFFFF), n);
    });
    m.other_requests.for_each([&](std::uint32_t key, std::uint64_t n) {
        line("fins_requests_total", fmt::format("command=\"other\",end_code=\"{:04X}\"", key), n);
    });
    if (const auto n = m.requests.overflow() + m.other_requests.overflow(); n != 0)
        line("fins_requests_total", "command=\"other\",end_code=\"other\"", n);

    const auto& h = m.request_duration;
    header(out, "fins_request_duration_seconds",
           "Time from a FINS request's destination check to its answer", "histogram");
    std::uint64_t cumulative = 0;
    for (std::size_t i = 0; i < Histogram::bounds.size(); ++i) {
        cumulative += h.bucket(i);
        line("fins_request_duration_seconds_bucket",
             fmt::format("le=\"{}\"", number(Histogram::bounds[i])), cumulative);
    }
    line("fins_request_duration_seconds_bucket", "le=\"+Inf\"", h.count());
    line("fins_request_duration_seconds_sum", "", number(static_cast<double>(h.sum_ns()) * 1e-9));
    line("fins_request_duration_seconds_count", "", h.count());

    header(out, "fins_udp_replies_dropped_total",
           "FINS/UDP replies dropped because the send buffer was full", "counter");
    line("fins_udp_replies_dropped_total", "", m.datagrams_dropped.load(std::memory_order_relaxed));

    header(out, "fins_relays_total", "Frames a plant's router took to pass to another node",
           "counter");
    line("fins_relays_total", "", m.relays.load(std::memory_order_relaxed));
    header(out, "fins_relay_errors_total", "Frames a router refused, by relay end code", "counter");
    m.relay_errors.for_each([&](std::uint32_t key, std::uint64_t n) {
        line("fins_relay_errors_total", fmt::format("end_code=\"{:04X}\"", key), n);
    });

    header(out, "fins_instructions_total",
           "PLC-initiated Send/Rcv/SendCmd completed, by completion code (0000 done)", "counter");
    m.instructions.for_each([&](std::uint32_t key, std::uint64_t n) {
        const auto kind = key >> 16;
        line("fins_instructions_total",
             fmt::format("instruction=\"{}\",completion=\"{:04X}\"",
                         kind < 3 ? instruction_names[kind] : "other", key & 0xFFFF),
             n);
    });

    header(out, "fins_http_requests_total", "HTTP requests answered by status", "counter");
    m.http_requests.for_each([&](std::uint32_t key, std::uint64_t n) {
        line("fins_http_requests_total", fmt::format("code=\"{}\"", key), n);
    });
    header(out, "fins_websocket_resyncs_total",
           "WebSocket clients that fell behind: queue dropped, snapshots sent", "counter");
    line("fins_websocket_resyncs_total", "", m.websocket_resyncs.load(std::memory_order_relaxed));
    header(out, "fins_web_handler_failures_total",
           "Web handlers that threw: answered 500 or closed, the server went on", "counter");
    line("fins_web_handler_failures_total", "",
         m.web_handler_failures.load(std::memory_order_relaxed));
    header(out, "fins_websocket_policy_closes_total",
           "WebSocket connections closed (1008) for sending more than their budget", "counter");
    line("fins_websocket_policy_closes_total", "",
         m.websocket_policy_closes.load(std::memory_order_relaxed));

    header(out, "fins_request_failures_total",
           "FINS requests whose handling failed with an exception (answered 0301 or dropped)",
           "counter");
    line("fins_request_failures_total", "", m.request_failures.load(std::memory_order_relaxed));
    header(out, "fins_control_failures_total",
           "Control requests whose handling failed with an exception (answered an error)",
           "counter");
    line("fins_control_failures_total", "", m.control_failures.load(std::memory_order_relaxed));

    for (const auto& f : extra) {
        header(out, f.name, f.help, f.type);
        for (const auto& s : f.samples)
            line(f.name, s.labels, number(s.value));
    }
    return out;
}

}  // namespace fins::server::metrics
