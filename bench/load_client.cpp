// fins_load --client: drives finsd through fins::Client (async_send pipelining, 32
// requests in flight) and reports its rate next to the raw-socket generator of load.cpp
// against the same finsd in the same run; the ratio is what the library costs on top of
// the bare sockets. Timing lives here, never in pass/fail tests.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <vector>

#include <time.h>

#include <fmt/core.h>

#include "fins/client.hpp"
#include "fins/commands/memory_area.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// CPU time of the calling thread, in microseconds: the generator and the client both run
// on this thread (finsd on its own), so their CPU per request compares them on a host too
// busy for their rates to mean much.
double thread_cpu_us() {
    timespec t{};
    ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e6 + static_cast<double>(t.tv_nsec) / 1e3;
}

struct ClientStatsLine {
    double rate = 0;
    double p50_us = 0;
    double p99_us = 0;
    std::size_t errors = 0;
    std::size_t count = 0;
    std::uint64_t waited_for_id = 0;  // requests that found no SID usable (ClientStats)
};

// Keeps `depth` 1-word reads of D0 in flight for `seconds`; each completion issues the
// next one from its callback, as a pipelining application would.
struct Pipeline {
    fins::Client& client;
    Clock::time_point end;
    std::vector<double> latencies;
    std::size_t errors = 0;

    void issue() {
        const auto sent = Clock::now();
        client.async_send(
            fins::MemoryAreaRead{{0x82, 0, 0}, 1},
            [this, sent](fins::Result<fins::MemoryAreaReadResponse> r) {
                const auto now = Clock::now();
                if (r)
                    latencies.push_back(
                        std::chrono::duration<double, std::micro>(now - sent).count());
                else
                    ++errors;
                if (now < end) issue();
            });
    }
};

ClientStatsLine drive_client(bool tcp, std::uint16_t port, unsigned depth, double seconds) {
    fins::ClientOptions options;
    options.port = port;
    options.protocol =
        tcp ? fins::ClientOptions::Protocol::tcp : fins::ClientOptions::Protocol::udp;
    options.timeout = std::chrono::milliseconds(1000);
    auto client = fins::Client::connect(options);
    if (!client) {
        std::fprintf(stderr, "fins_load: %s\n",
                     fins::describe_error(options, client.error()).c_str());
        return {};
    }
    const auto start = Clock::now();
    Pipeline p{
        **client,
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds)),
        {},
        0};
    p.latencies.reserve(1 << 21);
    for (unsigned i = 0; i < depth; ++i)
        p.issue();
    (*client)->run();
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    ClientStatsLine s;
    s.errors = p.errors;
    s.waited_for_id = (*client)->stats().waited_for_id;
    s.count = p.latencies.size();
    if (p.latencies.empty()) return s;
    std::sort(p.latencies.begin(), p.latencies.end());
    s.rate = static_cast<double>(p.latencies.size()) / elapsed;
    s.p50_us = p.latencies[p.latencies.size() / 2];
    s.p99_us = p.latencies[std::min(p.latencies.size() - 1, p.latencies.size() * 99 / 100)];
    return s;
}

}  // namespace

// Called by load.cpp's main for --client; `raw_rate` runs load.cpp's raw generator against
// the same finsd (transport, depth) and returns its requests per second.
int run_client_mode(std::uint16_t port, double seconds, bool json,
                    const std::function<double(bool tcp, unsigned depth)>& raw_rate) {
    constexpr unsigned depth = 32;
    for (const bool tcp : {false, true}) {
        const double cpu0 = thread_cpu_us();
        const double raw = raw_rate(tcp, depth);
        const double cpu1 = thread_cpu_us();
        const auto client = drive_client(tcp, port, depth, seconds);
        const double cpu2 = thread_cpu_us();
        const double ratio = raw > 0 ? client.rate / raw : 0;
        // The raw generator's count from its rate over the case's length (its last answers
        // take microseconds more).
        const double raw_count = raw * seconds;
        const double raw_cpu = raw_count > 0 ? (cpu1 - cpu0) / raw_count : 0;
        const double client_cpu =
            client.count > 0 ? (cpu2 - cpu1) / static_cast<double>(client.count) : 0;
        const char* proto = tcp ? "tcp" : "udp";
        if (json) {
            fmt::print(
                "{{\"mode\":\"client\",\"transport\":\"{}\",\"in_flight\":{},\"client_rps\":{:.0f},"
                "\"client_p50_us\":{:.1f},\"client_p99_us\":{:.1f},\"client_errors\":{},"
                "\"raw_rps\":{:.0f},\"ratio\":{:.2f},\"client_cpu_us\":{:.2f},\"raw_cpu_us\":{:.2f}"
                ","
                "\"waited_for_id\":{}}}\n",
                proto, depth, client.rate, client.p50_us, client.p99_us, client.errors, raw, ratio,
                client_cpu, raw_cpu, client.waited_for_id);
        } else {
            fmt::print(
                "{} in-flight {:>2}: fins::Client {:>8.0f} req/s p50 {:>6.1f} us p99 {:>6.1f} us "
                "errors {} | raw generator {:>8.0f} req/s | ratio {:.2f} | CPU per request: client "
                "{:.2f} us, raw {:.2f} us | waited for a SID {}\n",
                proto, depth, client.rate, client.p50_us, client.p99_us, client.errors, raw, ratio,
                client_cpu, raw_cpu, client.waited_for_id);
        }
        std::fflush(stdout);
        if (client.rate <= 0 || raw <= 0) return 1;
    }
    return 0;
}
