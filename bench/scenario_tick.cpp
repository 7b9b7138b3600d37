// fins_scenario_tick: the cost of scenario ticks at plant scale (issue 19, docs/benchmarks.md
// "Scenario ticks"). N CPU Units (plc::Plc on the heap, no sockets) each run a scenario of
// T tags: a quarter sines, a quarter random walks, a quarter lags toward a setpoint, a
// quarter links reading two other tags with noise(). Ticks every unit `--ticks` times and
// prints the CPU time per round of ticks and the share of one core at the tick period;
// then the same ticks in their three phases: what stays on finsd's I/O thread (the words
// in and out) and what its scenario thread computes.
//   fins_scenario_tick --units 1000 --tags 100 --tick-ms 100 --ticks 50
#include <chrono>
#include <cstdio>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "plc/plc.hpp"
#include "scenario/scenario.hpp"
#include "scenario_workload.hpp"

namespace {

double cpu_seconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"fins_scenario_tick: CPU cost of scenario ticks for a plant"};
    unsigned units = 1000, tags = 100, tick_ms = 100, ticks = 50;
    app.add_option("--units", units, "CPU Units")->check(CLI::Range(1u, 20000u));
    app.add_option("--tags", tags, "Tags per CPU Unit")->check(CLI::Range(4u, 10000u));
    app.add_option("--tick-ms", tick_ms, "Tick period")->check(CLI::Range(1u, 3600000u));
    app.add_option("--ticks", ticks, "Rounds of ticks to time")->check(CLI::Range(1u, 100000u));
    CLI11_PARSE(app, argc, argv);

    std::vector<std::unique_ptr<fins::plc::Plc>> plcs;
    std::vector<std::unique_ptr<fins::scenario::Scenario>> scenarios;
    for (unsigned u = 0; u < units; ++u) {
        plcs.push_back(std::make_unique<fins::plc::Plc>());
        auto s = fins::scenario::Scenario::compile(fins_bench::scenario_workload(tags, tick_ms, u),
                                                   *plcs.back());
        if (!s) {
            std::fprintf(stderr, "compile: %s\n", s.error().message.c_str());
            return 1;
        }
        scenarios.push_back(std::move(*s));
    }
    const auto now = std::chrono::system_clock::now();
    for (auto& s : scenarios)
        s->tick(now);  // warm-up
    const double start = cpu_seconds();
    for (unsigned k = 0; k < ticks; ++k)
        for (auto& s : scenarios)
            s->tick(now);
    const double per_round = (cpu_seconds() - start) / ticks;
    const double share = per_round / (tick_ms / 1000.0);
    fmt::print(
        "{} CPU Units x {} tags, tick {} ms: {:.2f} ms CPU per round of ticks "
        "({:.0f} ns per tag), {:.1f} % of one core\n",
        units, tags, tick_ms, per_round * 1e3, per_round * 1e9 / (double{1} * units * tags),
        share * 100);

    // With finsd's scenario thread the I/O thread runs only begin_tick and end_tick (the
    // words in and out); compute runs on the scenario thread. Timed here phase by phase,
    // each over every unit, on this one thread.
    double in_out = 0, computed = 0;
    for (unsigned k = 0; k < ticks; ++k) {
        const double t0 = cpu_seconds();
        for (auto& s : scenarios)
            s->begin_tick(now);
        const double t1 = cpu_seconds();
        for (auto& s : scenarios)
            s->compute();
        const double t2 = cpu_seconds();
        for (auto& s : scenarios)
            s->end_tick();
        in_out += (t1 - t0) + (cpu_seconds() - t2);
        computed += t2 - t1;
    }
    const double tags_total = double{1} * units * tags;
    fmt::print(
        "handed over: I/O thread {:.2f} ms per round ({:.0f} ns per tag, {:.1f} % of one core), "
        "scenario thread {:.2f} ms ({:.0f} ns per tag, {:.1f} %)\n",
        in_out / ticks * 1e3, in_out / ticks * 1e9 / tags_total,
        in_out / ticks / (tick_ms / 1000.0) * 100, computed / ticks * 1e3,
        computed / ticks * 1e9 / tags_total, computed / ticks / (tick_ms / 1000.0) * 100);
    return 0;
}
