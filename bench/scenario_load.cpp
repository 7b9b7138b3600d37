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
// one in flight the round trips' p50 and p99 (medians over the rounds).
//   fins_scenario_load --units 1000 --tags 100 --tick-ms 100 --seconds 1 --rounds 5
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
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
#include "fins_generator.hpp"
#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "scenario/scenario.hpp"
#include "scenario_workload.hpp"
#include "server/scenario/scenario_runner.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

// The Linux thread id of this process's thread named `name` (0: none).
pid_t thread_named(const std::string& name) {
    for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
        std::ifstream comm(task.path() / "comm");
        std::string line;
        if (std::getline(comm, line) && line == name)
            return static_cast<pid_t>(std::stol(task.path().filename().string()));
    }
    return 0;
}

// Seconds a thread of this process has run on a CPU (/proc/self/task/TID/schedstat).
double run_seconds(pid_t tid) {
    std::ifstream in("/proc/self/task/" + std::to_string(tid) + "/schedstat");
    double ns = 0;
    in >> ns;
    return ns * 1e-9;
}

double own_cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

bool pin(pid_t tid, int cpu) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return sched_setaffinity(tid, sizeof set, &set) == 0;
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
    bool pinned = false;
    app.add_flag("--pin", pinned,
                 "The I/O thread alone on CPU 0; the generator and the scenario thread on CPU "
                 "1 (as when the clients run on other hosts and finsd has 2 cores)");
    bool batched = false;
    app.add_flag("--batched", batched,
                 "The generator takes every arrived answer and sends as many requests in one "
                 "system call each (recvmmsg/sendmmsg, one recv/send on TCP): less CPU per "
                 "request than finsd, as clients on other hosts");
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
    std::promise<pid_t> io_tid;
    std::thread server_thread([&] {
        io_tid.set_value(static_cast<pid_t>(::gettid()));
        io.run();
    });
    const pid_t server_tid = io_tid.get_future().get();
    const pid_t worker_tid = worker ? thread_named(fins::server::ScenarioWorker::thread_name) : 0;
    if (pinned && (!pin(server_tid, 0) || !pin(0, 1) || (worker_tid != 0 && !pin(worker_tid, 1)))) {
        std::fprintf(stderr, "fins_scenario_load: cannot pin threads to CPUs 0 and 1\n");
        return 1;
    }

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

    fmt::print("{} CPU Units x {} tags at {} ms, computed on {}, {} rounds of {} s{}\n", units,
               tags, tick_ms, worker ? "finsd's scenario thread" : "the I/O thread", rounds,
               seconds,
               std::string(pinned ? ", I/O thread pinned to CPU 0, generator and scenario thread "
                                    "to CPU 1"
                                  : "") +
                   (batched ? ", batched generator" : ""));
    for (const bool tcp : {false, true}) {
        for (const unsigned depth : {1u, 32u}) {
            const auto frames = fins_bench::read_frames(tcp);
            const int fd =
                fins_bench::connect_to(tcp, tcp ? (*server)->tcp_port() : (*server)->udp_port());
            if (fd < 0 || (tcp && !fins_bench::tcp_handshake(fd))) {
                std::fprintf(stderr, "fins_scenario_load: cannot reach finsd\n");
                return 1;
            }
            std::vector<double> with, without, ratios, cpu_with, cpu_without;
            std::vector<double> p50_with, p50_without, p99_with, p99_without;
            std::vector<double> generator_with, generator_without, worker_cpu;
            for (unsigned round = 0; round < rounds; ++round) {
                double w = 0, wo = 0;
                for (const bool running : {round % 2 == 0, round % 2 != 0}) {
                    set_running(running);
                    const double before = fins_bench::cpu_seconds(server_thread);
                    const double own_before = own_cpu_seconds();
                    const double worker_before = worker_tid != 0 ? run_seconds(worker_tid) : 0;
                    const auto stats =
                        batched ? fins_bench::drive_batched(fd, tcp, frames, depth, seconds)
                                : fins_bench::drive(fd, tcp, frames, depth, seconds);
                    const double cpu = (fins_bench::cpu_seconds(server_thread) - before) / seconds;
                    (running ? generator_with : generator_without)
                        .push_back((own_cpu_seconds() - own_before) / seconds * 100);
                    if (running && worker_tid != 0)
                        worker_cpu.push_back((run_seconds(worker_tid) - worker_before) / seconds *
                                             100);
                    (running ? w : wo) = stats.rate;
                    (running ? cpu_with : cpu_without).push_back(cpu * 100);
                    (running ? p50_with : p50_without).push_back(stats.p50_us);
                    (running ? p99_with : p99_without).push_back(stats.p99_us);
                }
                with.push_back(w);
                without.push_back(wo);
                ratios.push_back(wo > 0 ? w / wo : 0);
            }
            ::close(fd);
            fmt::print(
                "{} in-flight {:>2}: paused {:>7.0f} req/s ({:.0f} % CPU) | running {:>7.0f} "
                "req/s ({:.0f} % CPU) | ratio {:.3f} | generator {:.0f} / {:.0f} % CPU{}\n",
                tcp ? "tcp" : "udp", depth, median(without), median(cpu_without), median(with),
                median(cpu_with), median(ratios), median(generator_without), median(generator_with),
                worker_cpu.empty() ? std::string()
                                   : fmt::format(", scenario thread {:.1f} %", median(worker_cpu)));
            if (depth == 1)
                fmt::print(
                    "{} in-flight  1 round trip: paused p50 {:.0f} us p99 {:.0f} us | running "
                    "p50 {:.0f} us p99 {:.0f} us\n",
                    tcp ? "tcp" : "udp", median(p50_without), median(p99_without), median(p50_with),
                    median(p99_with));
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
