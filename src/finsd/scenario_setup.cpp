// Starting a CPU Unit's scenario (contract in scenario_setup.hpp).
#include "finsd/scenario_setup.hpp"

#include <thread>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "scenario/scenario.hpp"

namespace fins::finsd {

tl::expected<void, std::string> override_scenario_time(Settings& settings, std::string_view time) {
    const bool virtual_time = time == "virtual";
    bool any = false;
    const auto set = [&](std::optional<ScenarioConfig>& config) {
        if (!config) return;
        set_scenario_time(*config, virtual_time);
        any = true;
    };
    set(settings.scenario);
    for (auto& cpu : settings.plant_cpu)
        set(cpu.scenario);
    if (!any)
        return tl::unexpected(
            fmt::format("--scenario-time {}: there is no scenario to run (give --scenario FILE, a "
                        "[scenario] table or a [plc.scenario]; docs/scenarios.md)",
                        time));
    return {};
}

std::string scenario_start_line(const ScenarioConfig& config) {
    const auto& def = config.def;
    const std::string where =
        config.reload_file.empty() ? std::string("(text)") : config.reload_file.string();
    const std::string plc = config.plc.empty() ? "" : fmt::format(" (plc {})", config.plc);
    const std::string time =
        def.virtual_time ? std::string("virtual time: moves by `finsd ctl scenario advance`")
                         : fmt::format("real time x{:g}", def.time_scale);
    const auto count = [](std::size_t n, std::string_view what) {
        return fmt::format("{} {}{}", n, what, n == 1 ? "" : "s");
    };
    return fmt::format("finsd: scenario {}{}: {}, {}, {}, tick {:g} ms", where, plc,
                       count(def.tags.size(), "tag"), count(def.events.size(), "event"), time,
                       def.tick_s * 1000.0);
}

std::unique_ptr<server::ScenarioRunner> run_scenario(
    asio::io_context& io, const std::optional<ScenarioConfig>& config,
    std::unique_ptr<scenario::Scenario> compiled, plc::Plc& plc, std::optional<double> phase,
    std::unique_ptr<server::ScenarioWorker>& worker) {
    if (!config || !compiled) return nullptr;
    spdlog::info("{}", scenario_start_line(*config));
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

}  // namespace fins::finsd
