// finsd's scenarios (issue 19; docs/scenarios.md): the [scenario] table of the finsd
// configuration, the same table in each [[plc]] of a plant, and `finsd --scenario FILE`
// (a file holding a [scenario] table). A table may name a file (`file = "tank.toml"`,
// relative to the file naming it) and add to it: its seed, tick_ms, time and time_scale
// replace the file's, its signals, links, inputs and events come after the file's.
//
// Every error reads "FILE:LINE:COLUMN: PATH: message" (PATH the dotted key, e.g.
// scenario.signal[2].kind); compile errors against the CPU Unit (unknown address,
// read-only area, type mismatch, link cycle, event on an unknown tag) read
// "FILE:LINE:COLUMN: message". finsd prints them and exits with code 2.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>
#include <tl/expected.hpp>

#include "scenario/definition.hpp"

namespace fins::plc {
class Plc;
}
namespace fins::scenario {
class Scenario;
}

namespace fins::finsd {

// Where a CPU Unit's real-time ticks are computed (`compute`): on finsd's scenario
// thread (server/scenario/scenario_worker.hpp), on the I/O thread with the requests, or
// auto: the scenario thread on a host of at least auto_thread_cores cores.
enum class ComputeOn { automatic, io_thread, scenario_thread };
inline constexpr unsigned auto_thread_cores = 2;

struct ScenarioConfig {
    scenario::ScenarioDef def;
    ComputeOn compute = ComputeOn::automatic;
    std::vector<std::string> sources;  // SourcePos::source -> file name
    // Where `finsd ctl scenario reload` reads it again: this file's [scenario] table, or
    // with `plc` the one of the [[plc]] of that name.
    std::filesystem::path reload_file;
    std::string plc;
    // finsd --scenario-time: replaces the file's `time` (true: virtual), on reload too.
    std::optional<bool> virtual_time;
};

// The [scenario] table `node` of `source` (path "scenario" or "plc[N].scenario").
tl::expected<ScenarioConfig, std::string> load_scenario_table(const toml::node& node,
                                                              std::string_view source,
                                                              const std::string& path);
// A file holding a [scenario] table (finsd --scenario FILE).
tl::expected<ScenarioConfig, std::string> load_scenario_file(const std::filesystem::path& file);
// A [scenario] table in TOML text (finskit.VirtualPlc(scenario=...)); `source` names it
// in errors, and a `file = ...` it names is relative to the working directory.
tl::expected<ScenarioConfig, std::string> load_scenario_text(std::string_view text,
                                                             std::string_view source);
// Sets the scenario's time, real or virtual, for this run and its reloads (--scenario-time).
void set_scenario_time(ScenarioConfig& config, bool virtual_time);
// Reads the scenario again from where it came from (reload_file, plc), with the time
// --scenario-time set.
tl::expected<ScenarioConfig, std::string> reload_scenario(const ScenarioConfig& old);
// Compiles the definition against `plc`, wording errors with their file position.
tl::expected<std::unique_ptr<scenario::Scenario>, std::string> compile_scenario(
    const ScenarioConfig& config, plc::Plc& plc);

}  // namespace fins::finsd
