// fins_scenario_load: finsd's FINS request rate with scenarios ticking, as a ratio of the
// rate without (issue 19, docs/benchmarks.md "Scenario ticks").
//
// finsd serves a plant of CPU Units on one I/O thread; every unit's scenario tick is
// handed over between that thread (the words in and out) and finsd's scenario thread (the
// tags computed), src/server/scenario/scenario_worker.hpp. This bench builds the same: a
// Server for one CJ2H (the unit the generator polls) plus --units CPU Units (that one
// included) each running the fins_scenario_tick scenario of --tags tags in real time at
// --tick-ms, each with its own ScenarioRunner and timer, as finsd runs them (their ticks in
// --groups phase groups spread over the period, finsd's ScenarioRunner::phase_of), and one
// ScenarioWorker (--no-worker: every tick computed on the I/O thread). The generator
// (this process's main thread, blocking sockets, as fins_load) keeps 1 or 32 1-word reads
// of D0 in flight over FINS/UDP and FINS/TCP; each round measures the rate with every
// scenario paused and with every scenario running (alternating which goes first), and the
// median ratio running / paused is printed with the server thread's CPU share, and with
// one in flight the round trips' p50 and p99.
//   fins_scenario_load --units 1000 --tags 100 --tick-ms 100 --seconds 1 --rounds 5
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "echo_server.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"
#include "fins/tcp.hpp"
#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "scenario/scenario.hpp"
#include "scenario_workload.hpp"
#include "server/scenario/scenario_runner.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// A 1-word MEMORY AREA READ of D0 from node 200 (with the FINS/TCP envelope on TCP).
std::vector<std::uint8_t> read_request(bool tcp) {
    std::array<std::uint8_t, 32> params{};
    fins::ByteWriter pw{params};
    fins::MemoryAreaRead{{0x82, 0, 0}, 1}.encode(pw);
    fins::Header h;
    h.destination = {0, 1, 0};
    h.source = {0, 200, 0};
    h.service_id = 1;
    std::vector<std::uint8_t> frame(fins::max_frame_size);
    frame.resize(
        fins::encode_request(h, fins::MemoryAreaRead::code, pw.written(), frame).value_or(0));
    if (!tcp) return frame;
    std::vector<std::uint8_t> out(fins::tcp_header_size);
    fins::ByteWriter w{out};
    fins::write_tcp_header(w, fins::TcpCommand::frame, frame.size());
    out.insert(out.end(), frame.begin(), frame.end());
    return out;
}

int connect_to(bool tcp, std::uint16_t port) {
    const int fd = ::socket(AF_INET, tcp ? SOCK_STREAM : SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(port);
    if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        if (fd >= 0) ::close(fd);
        return -1;
    }
    timeval tv{1, 0};  // a lost datagram ends the case instead of hanging it
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    if (!tcp) return fd;
    fins_bench::set_nodelay(fd);
    // FINS/TCP node address exchange: ask for node 200, the source node of the frames.
    std::array<std::uint8_t, 24> buf{};
    fins::ByteWriter w{buf};
    fins::write_node_address_request(w, 200);
    if (::send(fd, buf.data(), w.size(), MSG_NOSIGNAL) <= 0 ||
        !fins_bench::read_exact(fd, buf.data(), 24)) {
        ::close(fd);
        return -1;
    }
    return fd;
}

// Answers per second with `depth` requests outstanding for `seconds`; with one in flight,
// each answer's round trip in microseconds is appended to `round_trips`.
double drive(int fd, bool tcp, const std::vector<std::uint8_t>& request, std::size_t answer,
             unsigned depth, double seconds, std::vector<double>& round_trips) {
    std::vector<std::uint8_t> in(answer + 64);
    const auto start = Clock::now();
    const auto end =
        start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    std::size_t sent = 0, answered = 0;
    auto sent_at = start;
    auto send_one = [&] {
        ++sent;
        sent_at = Clock::now();
        return ::send(fd, request.data(), request.size(), MSG_NOSIGNAL) > 0;
    };
    for (unsigned i = 0; i < depth; ++i)
        if (!send_one()) return 0;
    bool sending = true;
    while (answered < sent) {
        const bool ok = tcp ? fins_bench::read_exact(fd, in.data(), answer)
                            : ::recv(fd, in.data(), in.size(), 0) > 0;
        if (!ok) break;
        ++answered;
        if (depth == 1)
            round_trips.push_back(
                std::chrono::duration<double, std::micro>(Clock::now() - sent_at).count());
        if (sending && Clock::now() < end) {
            if (!send_one()) break;
        } else {
            sending = false;
        }
    }
    return static_cast<double>(answered) /
           std::chrono::duration<double>(Clock::now() - start).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

double percentile(std::vector<double>& v, double p) {
    if (v.empty()) return 0;
    const auto at = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(at), v.end());
    return v[at];
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"fins_scenario_load: finsd's request rate with scenarios ticking vs paused"};
    unsigned units = 1000, tags = 100, tick_ms = 100, rounds = 3;
    double seconds = 2.0;
    app.add_option("--units", units, "CPU Units with a scenario on finsd's thread")
        ->check(CLI::Range(1u, 20000u))
        ->capture_default_str();
    app.add_option("--tags", tags, "Tags per CPU Unit")
        ->check(CLI::Range(4u, 10000u))
        ->capture_default_str();
    app.add_option("--tick-ms", tick_ms, "Tick period")
        ->check(CLI::Range(1u, 3600000u))
        ->capture_default_str();
    app.add_option("--seconds", seconds, "Each side of each round")
        ->check(CLI::Range(0.1, 60.0))
        ->capture_default_str();
    app.add_option("--rounds", rounds, "Rounds per case (medians are printed)")
        ->check(CLI::Range(1u, 101u))
        ->capture_default_str();
    unsigned groups = fins::server::ScenarioRunner::phase_groups;
    app.add_option("--groups", groups,
                   "Phase groups the units' ticks are spread over (finsd: the default; 1: "
                   "all at once)")
        ->check(CLI::Range(1u, 100000u))
        ->capture_default_str();
    bool use_worker = true;
    app.add_flag("!--no-worker", use_worker,
                 "Compute the ticks on the I/O thread (finsd before its scenario thread)");
    CLI11_PARSE(app, argc, argv);
    spdlog::set_level(spdlog::level::warn);

    asio::io_context io{1};
    // finsd's scenario thread (--no-worker: every tick on the I/O thread, as before).
    std::unique_ptr<fins::server::ScenarioWorker> worker;
    if (use_worker) worker = std::make_unique<fins::server::ScenarioWorker>(io);
    std::vector<std::unique_ptr<fins::plc::Plc>> plcs;
    std::vector<std::unique_ptr<fins::server::ScenarioRunner>> runners;
    for (unsigned u = 0; u < units; ++u) {
        plcs.push_back(std::make_unique<fins::plc::Plc>(fins::plc::cj2h()));
        auto def = fins_bench::scenario_workload(tags, tick_ms, u);
        def.virtual_time = false;
        auto compiled = fins::scenario::Scenario::compile(std::move(def), *plcs.back());
        if (!compiled) {
            std::fprintf(stderr, "compile: %s\n", compiled.error().message.c_str());
            return 1;
        }
        runners.push_back(std::make_unique<fins::server::ScenarioRunner>(
            io, std::move(*compiled),
            [] {
                return fins::server::ScenarioRunner::Compiled(
                    tl::unexpected(std::string("no file")));
            },
            "bench", worker.get()));
    }
    fins::server::ServerOptions options;
    options.port = 0;
    auto server = fins::server::Server::start(io, *plcs.front(), options);
    if (!server) {
        std::fprintf(stderr, "fins_scenario_load: cannot start finsd: %s\n",
                     server.error().message().c_str());
        return 1;
    }
    (*server)->dispatcher().attach_faults(runners.front().get());
    // As finsd starts a plant's scenarios: in groups spread over the period (--groups 1:
    // every unit's first tick now, all in one burst per period).
    for (std::size_t u = 0; u < runners.size(); ++u)
        runners[u]->start(static_cast<double>(u % groups) / groups);  // on the shared grid
    std::thread server_thread([&] { io.run(); });

    // Pauses or resumes every scenario on the I/O thread and waits until it has.
    auto set_running = [&](bool running) {
        std::promise<void> done;
        asio::post(io, [&] {
            for (auto& r : runners)
                running ? r->resume() : r->pause();
            done.set_value();
        });
        done.get_future().wait();
    };

    const std::size_t answer = fins::header_size + 2 + 2 + 2;  // header, cmd, end, 1 word
    fmt::print("{} CPU Units x {} tags at {} ms, computed on {}, {} rounds of {} s\n", units, tags,
               tick_ms, worker ? "finsd's scenario thread" : "the I/O thread", rounds, seconds);
    for (const bool tcp : {false, true}) {
        for (const unsigned depth : {1u, 32u}) {
            const auto request = read_request(tcp);
            const int fd = connect_to(tcp, tcp ? (*server)->tcp_port() : (*server)->udp_port());
            if (fd < 0) {
                std::fprintf(stderr, "fins_scenario_load: cannot reach finsd\n");
                return 1;
            }
            const std::size_t size = answer + (tcp ? fins::tcp_header_size : 0);
            std::vector<double> with, without, ratios, cpu_with, cpu_without;
            std::vector<double> trips_with, trips_without;
            for (unsigned round = 0; round < rounds; ++round) {
                double w = 0, wo = 0;
                for (const bool running : {round % 2 == 0, round % 2 != 0}) {
                    set_running(running);
                    const double before = fins_bench::cpu_seconds(server_thread);
                    const double rate = drive(fd, tcp, request, size, depth, seconds,
                                              running ? trips_with : trips_without);
                    const double cpu = (fins_bench::cpu_seconds(server_thread) - before) / seconds;
                    (running ? w : wo) = rate;
                    (running ? cpu_with : cpu_without).push_back(cpu * 100);
                }
                with.push_back(w);
                without.push_back(wo);
                ratios.push_back(wo > 0 ? w / wo : 0);
            }
            ::close(fd);
            fmt::print(
                "{} in-flight {:>2}: paused {:>7.0f} req/s ({:.0f} % CPU) | running {:>7.0f} "
                "req/s ({:.0f} % CPU) | ratio {:.3f}\n",
                tcp ? "tcp" : "udp", depth, median(without), median(cpu_without), median(with),
                median(cpu_with), median(ratios));
            if (depth == 1)
                fmt::print(
                    "{} in-flight  1 round trip: paused p50 {:.0f} us p99 {:.0f} us | running "
                    "p50 {:.0f} us p99 {:.0f} us\n",
                    tcp ? "tcp" : "udp", percentile(trips_without, 0.5),
                    percentile(trips_without, 0.99), percentile(trips_with, 0.5),
                    percentile(trips_with, 0.99));
        }
    }
    set_running(true);
    asio::post(io, [&] {
        for (auto& r : runners)
            r->stop();
        (*server)->stop();
        io.stop();
    });
    server_thread.join();
    return 0;
}
