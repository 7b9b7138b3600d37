// Starting a CPU Unit's scenario (contract in scenario_setup.hpp).
#include "cli/finsd/scenario_setup.hpp"

#include <thread>

#include "scenario/scenario.hpp"

namespace fins::cli::finsd {

std::unique_ptr<server::ScenarioRunner> run_scenario(
    asio::io_context& io, const std::optional<ScenarioConfig>& config,
    std::unique_ptr<scenario::Scenario> compiled, plc::Plc& plc, std::optional<double> phase,
    std::unique_ptr<server::ScenarioWorker>& worker) {
    if (!config || !compiled) return nullptr;
    // On one core a scenario thread only adds switches; from 2 cores on it takes the ticks
    // off the I/O thread (with clients on the same 2-core host as well: docs/benchmarks.md,
    // fins_scenario_load with and without --no-worker).
    // Virtual time ticks only when told (ctl advance), on this thread; a reload may turn it
    // to real time, so the choice does not look at `time`.
    const bool own_thread = config->compute == ComputeOn::scenario_thread ||
                            (config->compute == ComputeOn::automatic &&
                             std::thread::hardware_concurrency() >= auto_thread_cores);
    if (own_thread && !worker) worker = std::make_unique<server::ScenarioWorker>(io);
    auto reload = [where = *config, &plc]() -> server::ScenarioRunner::Compiled {
        auto fresh = reload_scenario(where);
        if (!fresh) return tl::unexpected(fresh.error());
        return compile_scenario(*fresh, plc);
    };
    auto runner = std::make_unique<server::ScenarioRunner>(
        io, std::move(compiled), std::move(reload), config->reload_file.string(),
        own_thread ? worker.get() : nullptr);
    runner->start(phase);
    return runner;
}

}  // namespace fins::cli::finsd
