// fins_web_plcs: how long one GET /api/plcs of a large plant holds the thread that also
// serves FINS (issue 27). --units CPU Units (CJ2H, named and addressed as a plant's:
// 250 nodes a network) behind finsd's HTTP front, and finsd's FINS/UDP server for the
// first of them, all on one io_context thread as in finsd. Each case runs --seconds:
//
//   idle     nothing but FINS: one 1-word MEMORY AREA READ in flight at a time (the
//            round trip of a unit polled by one client);
//   listing  the same, while a second thread fetches /api/plcs back to back.
//
// Per case: the FINS round trips' p50, p99 and max, and the longest hold of the I/O
// thread as a 1 ms probe timer on it sees it: how late the timer ran (max, wall time: it
// includes the thread being descheduled on a loaded machine) and the most CPU time the
// thread spent between two runs of the timer (max: what the handlers between took,
// whatever the scheduler did); for `listing`, the fetches done and their mean time.
// --listing-slice-ms: WebOptions::listing_slice (a large value builds the listing in one
// go, as before issue 27). Timing lives here, never in tests.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/core/tcp_stream.hpp>
#include <boost/beast/http.hpp>

#include "plc/plc.hpp"
#include "server/sessions/server.hpp"
#include "web/http_server.hpp"

#include "fins_generator.hpp"

namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using Clock = std::chrono::steady_clock;

double thread_cpu_ms() {
    timespec t{};
    ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}

double ms_since(Clock::time_point t, Clock::time_point now = Clock::now()) {
    return std::chrono::duration<double, std::milli>(now - t).count();
}

struct Case {
    std::vector<double> rtt_ms;   // FINS round trips
    double probe_max_ms = 0;      // the probe timer's worst lateness
    double probe_cpu_max_ms = 0;  // the I/O thread's most CPU time between two probes
    std::size_t fetches = 0;
    double fetch_ms = 0;  // mean
    bool ok = true;
};

// One request in flight to `port` for `seconds`: every round trip.
std::vector<double> fins_round_trips(std::uint16_t port, double seconds, bool& ok) {
    std::vector<double> out;
    const int fd = fins_bench::connect_to(false, port);
    if (fd < 0) {
        ok = false;
        return out;
    }
    const auto frame = fins_bench::read_frame(1);
    std::vector<std::uint8_t> in(256);
    const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(seconds));
    while (Clock::now() < end) {
        const auto t = Clock::now();
        if (::send(fd, frame.data(), frame.size(), 0) <= 0 ||
            ::recv(fd, in.data(), in.size(), 0) <= 0) {
            ok = false;  // SO_RCVTIMEO is 1 s: a datagram lost or held that long
            break;
        }
        out.push_back(ms_since(t));
    }
    ::close(fd);
    return out;
}

// GET /api/plcs over one keep-alive connection until `stop`; the count and mean time.
void fetch_loop(std::uint16_t port, std::size_t units, const std::atomic<bool>& stop, Case& c) {
    asio::io_context io;
    beast::tcp_stream stream(io);
    stream.connect(asio::ip::tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
    beast::flat_buffer buffer;
    double total = 0;
    while (!stop) {
        http::request<http::empty_body> req{http::verb::get, "/api/plcs", 11};
        req.set(http::field::host, "127.0.0.1");
        const auto t = Clock::now();
        http::write(stream, req);
        http::response_parser<http::string_body> parser;
        parser.body_limit(boost::none);
        http::read(stream, buffer, parser);
        total += ms_since(t);
        ++c.fetches;
        // A whole listing: every unit's entry is there.
        const auto& body = parser.get().body();
        if (parser.get().result() != http::status::ok ||
            body.find(fmt::format("\"plc{}\"", units)) == std::string::npos) {
            c.ok = false;
            return;
        }
    }
    c.fetch_ms = c.fetches > 0 ? total / static_cast<double>(c.fetches) : 0;
}

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<std::size_t>(static_cast<double>(v.size()) * p))];
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"fins_web_plcs: how long GET /api/plcs holds the FINS thread"};
    std::size_t units = 1000;
    double seconds = 3;
    bool json = false;
    double slice_ms = 1;
    app.add_option("--units", units, "CPU Units listed")->check(CLI::Range(1, 20000));
    app.add_option("--seconds", seconds, "per case")->check(CLI::Range(0.2, 60.0));
    app.add_flag("--json", json, "JSON lines");
    app.add_option("--listing-slice-ms", slice_ms, "WebOptions::listing_slice")
        ->check(CLI::Range(0.0, 3600e3));
    CLI11_PARSE(app, argc, argv);
    spdlog::set_level(spdlog::level::warn);

    std::vector<std::unique_ptr<fins::plc::Plc>> plcs;
    fins::web::WebContext context;
    for (std::size_t i = 0; i < units; ++i) {
        plcs.push_back(std::make_unique<fins::plc::Plc>(fins::plc::cj2h()));
        fins::server::ControlTarget t;
        t.plc = plcs.back().get();
        t.name = fmt::format("plc{}", i + 1);
        t.addresses = {
            {static_cast<std::uint8_t>(1 + i / 250), static_cast<std::uint8_t>(1 + i % 250)}};
        context.targets.push_back(t);
    }
    context.options.listing_slice =
        std::chrono::microseconds(static_cast<std::int64_t>(slice_ms * 1000));
    asio::io_context io{1};
    fins::server::ServerOptions options;
    options.port = 0;
    auto fins_server = fins::server::Server::start(io, *plcs.front(), options);
    if (!fins_server) {
        std::fprintf(stderr, "fins_web_plcs: cannot start the FINS server\n");
        return 1;
    }
    // What finsd's describe hook adds to an entry (finsd/web_setup.cpp): the relay
    // counts and the unit's ports (every unit here reports the one FINS server's).
    const auto* server = (*fins_server).get();
    context.describe = [server](const fins::server::ControlTarget&, nlohmann::json& entry) {
        entry["relays"] = nlohmann::json::object();
        entry["udp_port"] = server->udp_port();
        entry["tcp_port"] = server->tcp_port();
        entry["tcp_connections"] = server->tcp_connections();
    };
    auto web = fins::web::HttpServer::start(io, std::move(context));
    if (!web) {
        std::fprintf(stderr, "fins_web_plcs: cannot start the HTTP server\n");
        return 1;
    }
    // The probe: a 1 ms timer on the I/O thread; how late it runs is how long the thread
    // was held by something else.
    asio::steady_timer probe(io);
    double probe_max = 0;
    double probe_cpu_max = 0;
    double probe_cpu_last = -1;
    bool probing = true;
    std::function<void()> arm = [&] {
        probe.expires_after(std::chrono::milliseconds(1));
        probe.async_wait([&](boost::system::error_code ec) {
            if (ec || !probing) return;
            probe_max = std::max(probe_max, ms_since(probe.expiry()));
            const double cpu = thread_cpu_ms();
            if (probe_cpu_last >= 0) probe_cpu_max = std::max(probe_cpu_max, cpu - probe_cpu_last);
            probe_cpu_last = cpu;
            arm();
        });
    };
    arm();
    std::thread io_thread([&] { io.run(); });
    const auto on_io = [&](auto f) {
        std::promise<decltype(f())> p;
        asio::post(io, [&] { p.set_value(f()); });
        return p.get_future().get();
    };
    const std::uint16_t port = (*web)->port();
    const std::uint16_t fins_port = (*fins_server)->udp_port();

    bool all_ok = true;
    for (const bool listing : {false, true}) {
        on_io([&] {
            probe_cpu_max = 0;
            return probe_max = 0;
        });
        Case c;
        std::atomic<bool> stop{false};
        std::thread fetcher;
        if (listing) fetcher = std::thread([&] { fetch_loop(port, units, stop, c); });
        c.rtt_ms = fins_round_trips(fins_port, seconds, c.ok);
        stop = true;
        if (fetcher.joinable()) fetcher.join();
        c.probe_max_ms = on_io([&] { return probe_max; });
        c.probe_cpu_max_ms = on_io([&] { return probe_cpu_max; });
        all_ok = all_ok && c.ok && !c.rtt_ms.empty();
        const double max =
            c.rtt_ms.empty() ? 0 : *std::max_element(c.rtt_ms.begin(), c.rtt_ms.end());
        const char* name = listing ? "listing" : "idle";
        if (json)
            std::printf(
                "{\"units\":%zu,\"case\":\"%s\",\"fins_round_trips\":%zu,\"fins_p50_ms\":%.3f,"
                "\"fins_p99_ms\":%.3f,\"fins_max_ms\":%.3f,\"probe_max_ms\":%.3f,"
                "\"probe_cpu_max_ms\":%.3f,\"fetches\":%zu,\"fetch_ms\":%.1f,\"ok\":%s}\n",
                units, name, c.rtt_ms.size(), percentile(c.rtt_ms, 0.5), percentile(c.rtt_ms, 0.99),
                max, c.probe_max_ms, c.probe_cpu_max_ms, c.fetches, c.fetch_ms,
                c.ok ? "true" : "false");
        else
            std::printf(
                "%6zu units %-8s FINS %7zu round trips p50 %7.3f p99 %8.3f max %8.3f ms  "
                "I/O thread held max %8.3f ms (CPU %8.3f ms)  /api/plcs %3zu fetches, %7.1f ms "
                "each%s\n",
                units, name, c.rtt_ms.size(), percentile(c.rtt_ms, 0.5), percentile(c.rtt_ms, 0.99),
                max, c.probe_max_ms, c.probe_cpu_max_ms, c.fetches, c.fetch_ms,
                c.ok ? "" : "  FAILED");
    }
    on_io([&] {
        probing = false;
        probe.cancel();
        (*web)->stop();
        (*fins_server)->stop();
        return 0;
    });
    io.stop();
    io_thread.join();
    return all_ok ? 0 : 1;
}
