// `finsd ctl scenario status|pause|resume|advance SECONDS|trigger EVENT|reload` (with
// --plc NAME in a plant): the request lines of server/control/control_scenario.hpp.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace fins::finsd {

// Adds the `scenario` verb to `app`; parsing it fills `request`.
void add_scenario_verbs(CLI::App& app, nlohmann::json& request);

}  // namespace fins::finsd
