// `fins watch ADDRESS... [--interval S] [--count N] [--duration S]`: polls the addresses
// with one 01 04 MULTIPLE MEMORY AREA READ per turn (W342 5-3-5; split above 167 by the
// client) and prints each value the first time and whenever it changes:
//   text    "HH:MM:SS.mmm  D100  5" (host local time)
//   --json  one object per line: {"time": "YYYY-MM-DD HH:MM:SS.mmm", "address", "value"}
// It ends after N polls (--count), after S seconds (--duration), or on Ctrl-C / SIGTERM,
// each with exit 0; a failed poll ends it with that failure's exit code (3 or 4).
// Ctrl-C and SIGTERM are taken between polls (StopRequest), so a signal never interrupts
// a request half way and the output ends on a whole line.
#include <chrono>
#include <cstdio>
#include <ctime>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "cli/fins/stop_request.hpp"
#include "cli/fins/verb_support.hpp"
#include "fins/address.hpp"

namespace fins::cli {

namespace {

struct WatchArgs {
    std::vector<std::string> addresses;
    double interval_seconds = 1.0;
    unsigned count = 0;           // 0: no limit
    double duration_seconds = 0;  // 0: no limit
};

using Clock = std::chrono::steady_clock;

// Local wall-clock time with milliseconds: the date only in JSON (lines of a long run).
std::string now_text(bool with_date) {
    const auto now = std::chrono::system_clock::now();
    const std::time_t t = std::chrono::system_clock::to_time_t(now);
    const auto ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() %
        1000;
    std::tm tm{};
    ::localtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, with_date ? "%Y-%m-%d %H:%M:%S" : "%H:%M:%S", &tm);
    return fmt::format("{}.{:03}", buf, ms);
}

int run_watch(const GlobalOptions& g, const WatchArgs& a, Output& out) {
    std::vector<Address> addresses;
    for (const auto& text : a.addresses) {
        auto addr = parse_address(text);
        if (!addr)
            return out.usage(fmt::format("bad address '{}': {}", text, addr.error().message()));
        if (auto mem = to_memory_address(*addr); !mem)
            return out.usage(fmt::format("{}: {}", text, mem.error().message()));
        addresses.push_back(*addr);
    }
    // Before the client exists, so every thread it might start inherits the signal mask.
    StopRequest stop;

    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    const auto interval = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(a.interval_seconds));
    const auto start = Clock::now();
    const auto end = a.duration_seconds > 0
                         ? start + std::chrono::duration_cast<Clock::duration>(
                                       std::chrono::duration<double>(a.duration_seconds))
                         : Clock::time_point::max();
    std::vector<std::optional<std::uint32_t>> last(addresses.size());
    for (unsigned poll = 0; a.count == 0 || poll < a.count; ++poll) {
        auto values = client->read_multiple(addresses);
        if (!values) return out.failure(values.error(), "watch");
        for (std::size_t i = 0; i < addresses.size() && i < values->size(); ++i) {
            const auto v = (*values)[i];
            if (last[i] == v) continue;
            last[i] = v;
            const auto name = format_address(addresses[i]);
            out.print({{"time", now_text(true)}, {"address", name}, {"value", v}},
                      fmt::format("{}  {}  {}\n", now_text(false), name, v));
        }
        std::fflush(stdout);
        if (a.count != 0 && poll + 1 >= a.count) break;
        // Fixed rate: a slow poll shortens the next wait instead of shifting the rest.
        auto next = start + interval * (poll + 1);
        if (next > end) next = end;
        if (stop.requested_before(next) || Clock::now() >= end) break;
    }
    return exit_ok;
}

}  // namespace

void add_watch_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code) {
    auto a = std::make_shared<WatchArgs>();
    auto* c = verb(app, "watch", "Poll addresses and print each change (01 04)", g, exit_code, a,
                   &run_watch);
    c->add_option("addresses", a->addresses, "Addresses, e.g. D100 CIO10.03 T5")->required();
    c->add_option("--interval", a->interval_seconds, "Seconds between polls")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 86400.0));
    c->add_option("--count", a->count, "Stop after N polls (default: no limit)")
        ->check(CLI::Range(1U, 1'000'000'000U));
    c->add_option("--duration", a->duration_seconds, "Stop after S seconds (default: no limit)")
        ->check(CLI::Range(0.001, 31'536'000.0));
}

}  // namespace fins::cli
