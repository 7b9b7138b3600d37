// fins_soak: a bounded soak of a real finsd process. Starts `finsd --port 0` on
// 127.0.0.1, then for the given time runs verifying UDP and TCP clients (each owning
// its DM words, every answer checked), garbage datagrams and TCP churn with malformed
// streams (soak_clients.hpp). Every interval it prints the counts and finsd's resident
// memory (VmRSS in /proc/PID/status).
//
// Exit status 1 when any answer mismatched, finsd died or stalled (no verified answer
// in an interval), its RSS grew more than --max-rss-growth-mib over the first
// interval's, or it did not shut down cleanly (exit 0) on SIGTERM at the end.
// Timing and rates are reported, never judged: that belongs to fins_load.
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "integration/support/process.hpp"
#include "soak_clients.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using namespace fins::soak;

struct Options {
    std::string finsd;
    double minutes = 0;
    double seconds = 0;
    unsigned tcp = 16;
    unsigned udp = 64;
    unsigned churners = 4;
    unsigned churn_rate = 50;  // connections per second per churner
    unsigned garbage = 2;
    unsigned garbage_rate = 500;  // datagrams per second per sender
    double interval = 10;
    double max_rss_growth_mib = 16;
    std::uint64_t seed = 1;
    std::string log_level = "warn";  // finsd's --log-level
    std::string keep_log;            // finsd's log kept at this path (else a removed temp file)
};

// finsd as a child (tests/integration/support/process.hpp's Child): stdout and stderr in a log file
// that is shown when the run fails (a file, not a pipe: finsd logs to stdout, and a full
// pipe would block its one I/O thread).
class Finsd {
  public:
    Finsd(const Options& o, unsigned max_connections)
        : keep_(!o.keep_log.empty()),
          log_path_(keep_ ? o.keep_log : temp_path()),
          child_({o.finsd, "--bind", "127.0.0.1", "--port", "0", "--log-level", o.log_level,
                  "--max-connections", std::to_string(max_connections)},
                 log_path_) {}
    ~Finsd() {
        child_.kill(SIGKILL);
        if (!keep_) ::unlink(log_path_.c_str());
    }
    Finsd(const Finsd&) = delete;
    Finsd& operator=(const Finsd&) = delete;

    // The port from the "listening <port>" line; 0 when it does not come within 30 s.
    std::uint16_t wait_listening() {
        const auto deadline = Clock::now() + std::chrono::seconds(30);
        while (Clock::now() < deadline) {
            const auto left =
                std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
            const std::string line = child_.read_line(left);
            unsigned port = 0;
            if (std::sscanf(line.c_str(), "listening %u", &port) == 1 && port <= 65535)
                return static_cast<std::uint16_t>(port);
            if (!child_.running()) return 0;
        }
        return 0;
    }
    [[nodiscard]] pid_t pid() const { return child_.pid(); }
    [[nodiscard]] bool running() { return child_.running(); }
    [[nodiscard]] std::string how_it_ended() const {
        const int code = child_.exit_code();
        if (code > 128) return fmt::format("killed by signal {}", code - 128);
        return fmt::format("exit status {}", code);
    }
    [[nodiscard]] bool clean_exit() const { return child_.exit_code() == 0; }
    // SIGTERM, then up to 20 s for a clean exit (SIGKILL after).
    void terminate() {
        if (running()) child_.kill(SIGTERM, std::chrono::seconds(20));
    }
    // Resident set size in KiB, 0 when unknown.
    [[nodiscard]] std::uint64_t rss_kib() const {
        std::ifstream in(fmt::format("/proc/{}/status", pid()));
        std::string key;
        while (in >> key) {
            if (key == "VmRSS:") {
                std::uint64_t kib = 0;
                in >> kib;
                return kib;
            }
            in.ignore(4096, '\n');
        }
        return 0;
    }
    void print_log_tail() const {
        std::ifstream in(log_path_);
        std::vector<std::string> lines;
        for (std::string line; std::getline(in, line);)
            lines.push_back(line);
        const std::size_t from = lines.size() > 40 ? lines.size() - 40 : 0;
        std::fprintf(stderr, "soak: finsd's last log lines:\n");
        for (std::size_t i = from; i < lines.size(); ++i)
            std::fprintf(stderr, "  %s\n", lines[i].c_str());
    }

  private:
    static std::string temp_path() {
        char path[] = "/tmp/fins_soak_finsd.XXXXXX";
        const int fd = ::mkstemp(path);
        if (fd >= 0) ::close(fd);
        return path;
    }

    bool keep_;
    std::string log_path_;
    fins::test::Child child_;
};

double mib(std::uint64_t kib) {
    return static_cast<double>(kib) / 1024.0;
}

int run(const Options& o) {
    const auto duration = std::chrono::duration<double>(o.minutes * 60 + o.seconds);
    // W596 allows 16 connections by default; the churners need their own on top.
    Finsd finsd(o, std::min(254u, o.tcp + o.churners + 4));
    const Target target{finsd.wait_listening(), 1};
    if (target.port == 0) {
        std::fprintf(stderr, "soak: finsd (%s) did not report a port\n", o.finsd.c_str());
        finsd.print_log_tail();
        return 1;
    }
    std::printf(
        "soak: finsd (pid %d) listening on 127.0.0.1 port %u; %u TCP + %u UDP verifying "
        "clients, %u churners, %u garbage senders, %.0f s\n",
        static_cast<int>(finsd.pid()), target.port, o.tcp, o.udp, o.churners, o.garbage,
        duration.count());
    std::fflush(stdout);

    Stats stats;
    std::atomic<bool> stop{false};
    std::atomic<int> ready{0};
    std::vector<std::thread> threads;
    // DM words in blocks of 256 per verifying client (80 clients: D0-D20479).
    const std::uint16_t block = 256;
    unsigned client = 0;
    for (unsigned i = 0; i < o.tcp; ++i, ++client)
        threads.emplace_back(
            run_tcp_client, target, Range{static_cast<std::uint16_t>(client * block), block},
            o.seed * 1000 + client, std::ref(stats), std::ref(ready), std::cref(stop));
    // The verifying TCP clients take their connections before the churn starts.
    const auto ready_deadline = Clock::now() + std::chrono::seconds(30);
    while (ready < static_cast<int>(o.tcp) && stats.mismatches == 0 &&
           Clock::now() < ready_deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    for (unsigned i = 0; i < o.udp; ++i, ++client)
        threads.emplace_back(run_udp_client, target,
                             Range{static_cast<std::uint16_t>(client * block), block},
                             static_cast<std::uint8_t>(2 + i), o.seed * 1000 + client,
                             std::ref(stats), std::cref(stop));
    for (unsigned i = 0; i < o.garbage; ++i)
        threads.emplace_back(run_garbage_sender, target, o.garbage_rate, o.seed * 7919 + i,
                             std::ref(stats), std::cref(stop));
    for (unsigned i = 0; i < o.churners; ++i)
        threads.emplace_back(run_churner, target, o.churn_rate, o.seed * 104729 + i,
                             std::ref(stats), std::cref(stop));

    const auto start = Clock::now();
    const auto interval = std::chrono::duration<double>(o.interval);
    auto next = start;
    std::uint64_t last_verified = 0;
    std::uint64_t baseline = 0;
    std::uint64_t peak = 0;
    std::uint64_t rss = 0;
    std::vector<std::string> failures;
    while (failures.empty()) {
        const auto left = duration - (Clock::now() - start);
        if (left <= decltype(left)::zero()) break;
        next += std::chrono::duration_cast<Clock::duration>(interval);
        std::this_thread::sleep_until(
            std::min(next, Clock::now() + std::chrono::duration_cast<Clock::duration>(left)));
        if (!finsd.running()) {
            failures.push_back("finsd died: " + finsd.how_it_ended());
            break;
        }
        rss = finsd.rss_kib();
        if (baseline == 0) baseline = rss;
        peak = std::max(peak, rss);
        const auto verified = stats.udp_verified + stats.tcp_verified;
        const double t = std::chrono::duration<double>(Clock::now() - start).count();
        std::printf(
            "t=%5.0fs verified %llu (UDP %llu, TCP %llu) mismatches %llu errors %llu "
            "garbage %llu (answered %llu) churn %llu (malformed %llu, resets %llu) RSS %.1f MiB\n",
            t, static_cast<unsigned long long>(verified),
            static_cast<unsigned long long>(stats.udp_verified.load()),
            static_cast<unsigned long long>(stats.tcp_verified.load()),
            static_cast<unsigned long long>(stats.mismatches.load()),
            static_cast<unsigned long long>(stats.errors.load()),
            static_cast<unsigned long long>(stats.garbage_datagrams.load()),
            static_cast<unsigned long long>(stats.garbage_answers.load()),
            static_cast<unsigned long long>(stats.connections.load()),
            static_cast<unsigned long long>(stats.malformed_streams.load()),
            static_cast<unsigned long long>(stats.resets.load()), mib(rss));
        std::fflush(stdout);
        if (stats.mismatches > 0) failures.push_back("mismatches");
        // Without verifying clients (--tcp 0 --udp 0: churn or garbage only) nothing is verified.
        if (o.tcp + o.udp > 0 && verified == last_verified)
            failures.push_back("stalled: no verified answer in an interval");
        last_verified = verified;
    }
    stop = true;
    for (auto& th : threads)
        th.join();
    const auto elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (stats.mismatches > 0 && failures.empty()) failures.push_back("mismatches");
    if (finsd.running()) {
        rss = finsd.rss_kib();
        peak = std::max(peak, rss);
    }
    if (baseline != 0 && mib(peak - std::min(peak, baseline)) > o.max_rss_growth_mib)
        failures.push_back(fmt::format("RSS grew {:.1f} MiB (bound {:.1f})", mib(peak - baseline),
                                       o.max_rss_growth_mib));
    const bool was_running = finsd.running();
    finsd.terminate();
    if (was_running && !finsd.clean_exit())
        failures.push_back("finsd did not shut down cleanly on SIGTERM: " + finsd.how_it_ended());

    const auto verified = stats.udp_verified + stats.tcp_verified;
    std::printf(
        "soak: %.0f s, %llu answers verified (%.0f/s), %llu mismatches, %llu errors, %llu garbage "
        "datagrams, %llu connections churned (%llu malformed), finsd RSS %.1f -> %.1f MiB "
        "(peak %.1f)\n",
        elapsed, static_cast<unsigned long long>(verified), static_cast<double>(verified) / elapsed,
        static_cast<unsigned long long>(stats.mismatches.load()),
        static_cast<unsigned long long>(stats.errors.load()),
        static_cast<unsigned long long>(stats.garbage_datagrams.load()),
        static_cast<unsigned long long>(stats.connections.load()),
        static_cast<unsigned long long>(stats.malformed_streams.load()), mib(baseline), mib(rss),
        mib(peak));
    if (failures.empty()) return 0;
    for (const auto& f : failures)
        std::fprintf(stderr, "soak: FAILED: %s\n", f.c_str());
    finsd.print_log_tail();
    return 1;
}

}  // namespace

int main(int argc, char** argv) {
    Options o;
    CLI::App app{"fins_soak: a bounded soak of a finsd process"};
    app.add_option("--finsd", o.finsd, "The finsd program to start")->required();
    app.add_option("--minutes", o.minutes, "Duration in minutes (adds to --seconds)");
    app.add_option("--seconds", o.seconds, "Duration in seconds (adds to --minutes)");
    app.add_option("--tcp", o.tcp, "Verifying FINS/TCP clients")->check(CLI::Range(0, 200));
    app.add_option("--udp", o.udp, "Verifying FINS/UDP clients")->check(CLI::Range(0, 200));
    app.add_option("--churners", o.churners, "Threads opening, abusing and closing connections");
    app.add_option("--churn-rate", o.churn_rate, "Connections per second per churner");
    app.add_option("--garbage", o.garbage, "Threads sending garbage datagrams");
    app.add_option("--garbage-rate", o.garbage_rate, "Datagrams per second per garbage sender");
    app.add_option("--interval", o.interval, "Seconds between reports")
        ->check(CLI::Range(0.5, 3600.0));
    app.add_option("--max-rss-growth-mib", o.max_rss_growth_mib,
                   "Fail when finsd's RSS grows more than this over the first report's");
    app.add_option("--seed", o.seed, "Seed of every client's random choices");
    app.add_option("--finsd-log-level", o.log_level, "finsd's --log-level")
        ->capture_default_str()
        ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
    app.add_option("--keep-log", o.keep_log,
                   "Keep finsd's log (stderr and stdout) in this file, e.g. to measure its size");
    CLI11_PARSE(app, argc, argv);
    if (o.minutes * 60 + o.seconds <= 0) o.seconds = 60;
    // 256 DM words per verifying client within DM's 32,768.
    if (o.tcp + o.udp > 128) {
        std::fprintf(stderr, "fins_soak: at most 128 verifying clients\n");
        return 2;
    }
    ::signal(SIGPIPE, SIG_IGN);
    return run(o);
}
