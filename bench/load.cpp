// fins_load: drives finsd with 1-word MEMORY AREA READs over FINS/UDP and FINS/TCP with
// 1 and 32 requests in flight, and measures a raw loopback echo of the same frame sizes
// in the same run, so the ratio tells what finsd costs over the kernel's own loopback.
// One more TCP case is a client that writes the FINS/TCP header and the frame in two
// writes without TCP_NODELAY (its second write waits for the server's ACK of the first).
//
// Both servers run in this process on one thread each (finsd is single-threaded too);
// the generator uses blocking sockets on the main thread. Output: one line per case,
// or JSON with --json. Timing lives here, never in pass/fail tests.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <pthread.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>

#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"
#include "fins/tcp.hpp"
#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "server/sessions/server.hpp"

#include "echo_server.hpp"
#include "fins_generator.hpp"
#include "transport/asio.hpp"

namespace {

using namespace fins_bench;

// Each field's median over the runs (rate, p50, p99 and CPU per request separately).
Stats median_stats(std::vector<Stats> runs) {
    auto median = [&](auto field) {
        std::vector<double> v;
        for (const auto& r : runs)
            v.push_back(field(r));
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
    };
    Stats s;
    s.rate = median([](const Stats& r) { return r.rate; });
    s.p50_us = median([](const Stats& r) { return r.p50_us; });
    s.p99_us = median([](const Stats& r) { return r.p99_us; });
    s.count = 1'000'000;
    s.cpu_us = median([](const Stats& r) { return r.cpu_per_request_us(); }) * 1e6;
    return s;
}

}  // namespace

// bench/load_client.cpp: --client mode.
int run_client_mode(std::uint16_t port, double seconds, bool json,
                    const std::function<double(bool tcp, unsigned depth)>& raw_rate);

int main(int argc, char** argv) {
    CLI::App app{"fins_load: finsd request rate vs a raw loopback echo"};
    double seconds = 2.0;
    bool json = false;
    std::string udp_echo = "batched";
    app.add_option("--seconds", seconds, "Duration of each case")->capture_default_str();
    app.add_flag("--json", json, "Print JSON lines");
    app.add_option("--udp-echo", udp_echo,
                   "The UDP echo: batched (recvmmsg/sendmmsg) or per-datagram (recvfrom/sendto)")
        ->check(CLI::IsMember({"batched", "per-datagram"}))
        ->capture_default_str();
    unsigned rounds = 1;
    app.add_option("--rounds", rounds,
                   "Alternate finsd and the echo this many times per case (each seconds/rounds); "
                   "medians are printed")
        ->capture_default_str()
        ->check(CLI::Range(1u, 101u));
    std::vector<std::string> cases;
    app.add_option("--case", cases, "Run only these cases (default all)")
        ->check(CLI::IsMember({"udp-1", "udp-32", "tcp-1", "tcp-32", "tcp-split-1"}));
    bool client_mode = false;
    app.add_flag("--client", client_mode,
                 "Drive finsd through fins::Client (32 in flight) next to the raw generator");
    CLI11_PARSE(app, argc, argv);
    spdlog::set_level(spdlog::level::warn);

    fins::plc::Plc plc{fins::plc::cj2h()};
    asio::io_context io{1};
    fins::server::ServerOptions options;
    options.port = 0;
    auto server = fins::server::Server::start(io, plc, options);
    if (!server) {
        std::fprintf(stderr, "fins_load: cannot start finsd: %s\n",
                     server.error().message().c_str());
        return 1;
    }
    std::thread server_thread([&] { io.run(); });

    if (client_mode) {
        const int rc =
            run_client_mode((*server)->tcp_port(), seconds, json, [&](bool tcp, unsigned depth) {
                const Frames f = read_frames(tcp);
                const int fd = connect_to(tcp, (*server)->tcp_port());
                if (fd < 0 || (tcp && !tcp_handshake(fd))) return 0.0;
                const double rate = drive(fd, tcp, f, depth, seconds).rate;
                ::close(fd);
                return rate;
            });
        (*server)->stop();
        io.stop();
        server_thread.join();
        return rc;
    }
    for (const bool tcp : {false, true}) {
        const Frames f = read_frames(tcp);
        // TCP adds the split-write client: header and frame in two writes, no TCP_NODELAY.
        struct Shape {
            unsigned depth;
            bool split;
        };
        const auto shapes = tcp ? std::vector<Shape>{{1, false}, {32, false}, {1, true}}
                                : std::vector<Shape>{{1, false}, {32, false}};
        for (const auto& shape : shapes) {
            // Named copies, not a structured binding: clang 14 cannot capture one in a lambda.
            const unsigned depth = shape.depth;
            const bool split = shape.split;
            const std::string name =
                fmt::format("{}{}-{}", tcp ? "tcp" : "udp", split ? "-split" : "", depth);
            if (!cases.empty() && std::find(cases.begin(), cases.end(), name) == cases.end())
                continue;
            EchoServer echo(tcp, f.request.size(), f.response_size,
                            {.udp_batched = udp_echo == "batched", .quickack = split});
            // Rounds alternate which side goes first, so a load that rises or falls during
            // the case weighs on both alike; the medians are reported.
            const double slice = seconds / rounds;
            const int fd = connect_to(tcp, (*server)->tcp_port(), !split);
            if (fd < 0 || (tcp && !tcp_handshake(fd))) {
                std::fprintf(stderr, "fins_load: cannot reach finsd\n");
                return 1;
            }
            const int efd = connect_to(tcp, echo.port(), !split);
            std::vector<Stats> finsd_runs, echo_runs;
            std::vector<double> ratios;
            for (unsigned round = 0; round < rounds; ++round) {
                Stats one_finsd, one_echo;
                auto run_finsd = [&] {
                    const double before = cpu_seconds(server_thread);
                    one_finsd = drive(fd, tcp, f, depth, slice, split);
                    one_finsd.cpu_us = (cpu_seconds(server_thread) - before) * 1e6;
                };
                auto run_echo = [&] {
                    const double before = echo.cpu();
                    one_echo = drive(efd, tcp, f, depth, slice, split);
                    one_echo.cpu_us = (echo.cpu() - before) * 1e6;
                };
                if (round % 2 == 1) run_echo();
                run_finsd();
                if (round % 2 == 0) run_echo();
                finsd_runs.push_back(one_finsd);
                echo_runs.push_back(one_echo);
                ratios.push_back(one_echo.rate > 0 ? one_finsd.rate / one_echo.rate : 0);
            }
            ::close(fd);
            ::close(efd);
            const Stats finsd = median_stats(finsd_runs);
            const Stats raw = median_stats(echo_runs);
            std::sort(ratios.begin(), ratios.end());
            const double ratio = ratios[ratios.size() / 2];
            const double p99_ratio = raw.p99_us > 0 ? finsd.p99_us / raw.p99_us : 0;
            const char* proto = !tcp ? "udp" : split ? "tcp-split" : "tcp";
            if (json) {
                fmt::print(
                    "{{\"transport\":\"{}\",\"in_flight\":{},\"finsd_rps\":{:.0f},"
                    "\"finsd_p50_us\":{:.1f},\"finsd_p99_us\":{:.1f},\"echo_rps\":{:.0f},"
                    "\"echo_p50_us\":{:.1f},\"echo_p99_us\":{:.1f},\"ratio\":{:.2f},"
                    "\"finsd_cpu_us_per_request\":{:.2f},\"echo_cpu_us_per_request\":{:.2f},"
                    "\"p99_ratio\":{:.2f},\"rounds\":{}}}\n",
                    proto, depth, finsd.rate, finsd.p50_us, finsd.p99_us, raw.rate, raw.p50_us,
                    raw.p99_us, ratio, finsd.cpu_per_request_us(), raw.cpu_per_request_us(),
                    p99_ratio, rounds);
            } else {
                fmt::print(
                    "{:<9} in-flight {:>2}: finsd {:>8.0f} req/s p50 {:>6.1f} us p99 {:>6.1f} us | "
                    "echo {:>8.0f} req/s p50 {:>6.1f} us p99 {:>6.1f} us | ratio {:.2f} p99 "
                    "x{:.2f} | "
                    "cpu/req finsd {:.2f} us echo {:.2f} us\n",
                    proto, depth, finsd.rate, finsd.p50_us, finsd.p99_us, raw.rate, raw.p50_us,
                    raw.p99_us, ratio, p99_ratio, finsd.cpu_per_request_us(),
                    raw.cpu_per_request_us());
            }
            std::fflush(stdout);
        }
    }
    (*server)->stop();
    io.stop();
    server_thread.join();
    return 0;
}
