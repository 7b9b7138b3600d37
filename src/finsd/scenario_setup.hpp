// A CPU Unit's scenario, compiled at start (config_scenario.hpp), set running on the
// server's io_context (server/scenario/scenario_runner.hpp), with a reload that reads
// its file again and compiles it against the same CPU Unit.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <boost/asio/io_context.hpp>

#include "finsd/config.hpp"
#include "finsd/config_scenario.hpp"
#include "server/scenario/scenario_runner.hpp"
#include "transport/asio.hpp"

namespace fins::finsd {

// finsd --scenario-time real|virtual: the time of every scenario of this finsd
// ([scenario], --scenario, each [plc.scenario]), for its reloads too. An error when
// there is no scenario to set.
tl::expected<void, std::string> override_scenario_time(Settings& settings, std::string_view time);

// The start's log line of a scenario (info): "finsd: scenario FILE[ (plc NAME)]: N tags,
// M events, real time x1, tick 100 ms" (or "virtual time: moves by `finsd ctl scenario
// advance`").
std::string scenario_start_line(const ScenarioConfig& config);

// Null when `config` is empty. Starts the runner (`phase`: ScenarioRunner::start) with
// its ticks computed where `compute` says: on `worker` (finsd's one scenario thread, made
// on first use; it must outlive the runners) or on the I/O thread.
std::unique_ptr<server::ScenarioRunner> run_scenario(
    asio::io_context& io, const std::optional<ScenarioConfig>& config,
    std::unique_ptr<scenario::Scenario> compiled, plc::Plc& plc, std::optional<double> phase,
    std::unique_ptr<server::ScenarioWorker>& worker);

}  // namespace fins::finsd
