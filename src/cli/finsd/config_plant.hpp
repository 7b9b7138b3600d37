// finsd's plant configuration: [[plc]] tables, each a CPU Unit with its [[plc.ethernet]]
// Communications Units and [[plc.relay]] relay-table entries (README "A plant of several
// networks"). With at least one [[plc]], finsd runs the plant instead of the one node
// the top-level keys describe; the [network] TCP limits apply to every unit.
#pragma once

#include <string_view>

#include <toml++/toml.h>

#include "cli/finsd/config.hpp"

namespace fins::cli::finsd {

// Parses the array of [[plc]] tables at `node` (key `key` of file `source`) onto
// settings.plant, every error naming the file position and the dotted key.
Expected<void> load_plant(const toml::key& key, const toml::node& node, std::string_view source,
                          Settings& settings);

}  // namespace fins::cli::finsd

namespace fins::cli::finsd {

// Runs the plant of settings.plant until SIGINT/SIGTERM: prints "listening <port>" (the
// first unit's port) once every unit is bound. Exit codes as finsd's (main.cpp).
int serve_plant(const Settings& settings);

}  // namespace fins::cli::finsd
