// finsd's plant configuration: [[plc]] tables, each a CPU Unit with its [[plc.ethernet]]
// Communications Units, [[plc.relay]] relay-table entries and, read by the single node's
// loaders, its own [plc.memory], [plc.protection], [plc.inject], [plc.storage],
// [plc.files], [plc.serial], [[plc.remote]] and [[plc.schedule]] (docs/networks.md "A plant
// of several networks"). With at least one [[plc]], finsd runs the plant instead of the one node
// the top-level keys describe; the [network] TCP limits apply to every unit.
#pragma once

#include <string_view>

#include <toml++/toml.h>

#include "finsd/config.hpp"

namespace fins::finsd {

// The single node's [network] keys as one Ethernet unit, for server::options_for.
server::PlantPortConfig single_unit(const Settings& settings);
// The [network] FINS/TCP limits (the single node's, and every unit's of a plant).
server::TcpLimits tcp_limits(const Settings& settings);

// An error of a single node's loader or check ("FILE:L:C: serial.cpu: why", "FILE:L:C:
// serial port cpu: why") renamed for the plant's key `path`: "FILE:L:C:
// plc[1].serial.cpu: why", "FILE:L:C: plc[1]: serial port cpu: why".
Error in_plant(const Error& error, std::string_view path);

// Parses the array of [[plc]] tables at `node` (key `key` of file `source`) onto
// settings.plant, every error naming the file position and the dotted key.
Expected<void> load_plant(const toml::key& key, const toml::node& node, std::string_view source,
                          Settings& settings);

}  // namespace fins::finsd
