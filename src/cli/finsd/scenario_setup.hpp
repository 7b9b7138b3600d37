// A CPU Unit's scenario, compiled at start (config_scenario.hpp), set running on the
// server's io_context (server/scenario/scenario_runner.hpp), with a reload that reads
// its file again and compiles it against the same CPU Unit.
#pragma once

#include <memory>
#include <optional>

#include <boost/asio/io_context.hpp>

#include "cli/finsd/config_scenario.hpp"
#include "server/scenario/scenario_runner.hpp"
#include "transport/asio.hpp"

namespace fins::cli::finsd {

// Null when `config` is empty. Starts the runner (`phase`: ScenarioRunner::start) with
// its ticks computed where `compute` says: on `worker` (finsd's one scenario thread, made
// on first use; it must outlive the runners) or on the I/O thread.
std::unique_ptr<server::ScenarioRunner> run_scenario(
    asio::io_context& io, const std::optional<ScenarioConfig>& config,
    std::unique_ptr<scenario::Scenario> compiled, plc::Plc& plc, std::optional<double> phase,
    std::unique_ptr<server::ScenarioWorker>& worker);

}  // namespace fins::cli::finsd
