// finsd's settings: defaults, then the TOML file of --config, then command-line flags
// (flags override the file). Parsing and validation only; no sockets, no files except
// load_config_file() reading its one file, so everything here is unit-tested directly.
//
// Every error is one line naming the key and, for file keys, the file, line and column:
//   "finsd.toml:12:1: protection.network_write: 'some' is not off, all, listed or
//    all-except-listed"
// finsd prints it and exits with code 2. docs/finsd.md ("Configuration file reference") lists every
// key.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <tl/expected.hpp>

#include "finsd/config_http.hpp"

#include "fins/address.hpp"
#include "finsd/config_scenario.hpp"
#include "finsd/config_schedule.hpp"
#include "finsd/config_serial.hpp"
#include "plc/injections.hpp"
#include "plc/io_memory.hpp"
#include "plc/plc.hpp"
#include "server/routing/plant.hpp"

namespace fins::finsd {

// One [memory] entry: values written from `address` on, at start-up.
struct MemoryInit {
    std::string key;    // as written, e.g. "D100" (for messages)
    std::string where;  // "file:line:column" of the entry
    std::string path;   // its dotted key, e.g. memory."D100" or plc[1].memory."D100"
    Address address;
    // Element values: 0/1 for bits, 0-FFFF for words (negative -32768..-1 accepted as
    // two's complement), 0-FFFFFFFF for IR.
    std::vector<std::uint32_t> values;
};

// What a CPU Unit is given at start that a plant's [[plc]] also sets for itself:
// [protection] and [inject] (one loader, one apply_cpu_options for both).
struct CpuUnitOptions {
    plc::NetworkWriteProtectionSetting network_write_protection;
    bool um_read_protection = false;
    std::string um_password;            // [protection] password: releases UM read protection (ctl)
    bool dip_write_protection = false;  // DIP switch pin 1 ON
    plc::Injections inject;             // [inject]
};

// [files] (card_kbytes, em_file_bank, cassette): server::FileMemoryOptions, the same
// table as each [[plc]]'s [plc.files].
struct Settings : CpuUnitOptions, server::FileMemoryOptions {
    std::string profile = "cj2h";
    plc::OperatingMode mode = plc::OperatingMode::run;
    std::optional<std::filesystem::path> data_dir;
    std::optional<std::filesystem::path> control_socket;
    std::string log_level = "info";

    // [network]
    std::string bind = "127.0.0.1";
    std::uint16_t port = 9600;
    std::uint8_t node = 0;  // 0 = derive from bind
    std::uint8_t network = 0;
    bool udp = true;
    bool tcp = true;
    std::size_t max_connections = 16;
    // FINS/TCP limits in seconds (server/sessions/tcp_limits.hpp; idle and keep-alive 0 = off).
    unsigned tcp_handshake_timeout = 10;
    unsigned tcp_frame_timeout = 10;
    unsigned tcp_idle_timeout = 300;
    unsigned tcp_keepalive = 60;
    std::size_t tcp_max_pending = 16;

    // [storage]
    plc::Durability durability = plc::Durability::process;
    bool reset_state = false;  // --reset-state only: a refused state file is moved aside

    std::vector<MemoryInit> memory;        // [memory]
    std::vector<SerialPortConfig> serial;  // [serial], --serial (config_serial.hpp)
    server::PlantConfig plant;             // [[plc]] (config_plant.hpp); empty: one node
    // What each [[plc]] sets beyond server::PlantCpuConfig, in the order of plant.cpus
    // (the server layer knows no config entries; serve_plant applies them).
    struct PlantCpuSettings : CpuUnitOptions {  // [plc.protection], [plc.inject]
        std::vector<MemoryInit> memory;         // [plc.memory]
        std::vector<SerialPortConfig> serial;   // [plc.serial]
        std::vector<ScheduleEntry> schedule;    // [[plc.schedule]]
        // [plc.scenario] (config_scenario.hpp)
        std::optional<ScenarioConfig> scenario;
        // Per [[plc.ethernet]]: true when it sets `port`; the others take `port` above
        // (--port, [network] port).
        std::vector<bool> port_given;
    };
    std::vector<PlantCpuSettings> plant_cpu;

    // PLC-initiated messages (config_schedule.hpp).
    std::vector<server::RemoteNode> remotes;  // [[remote]]
    std::vector<ScheduleEntry> schedule;      // [[schedule]]

    HttpSettings http;  // [http], --http (config_http.hpp, docs/web.md)

    // [scenario], --scenario (config_scenario.hpp)
    std::optional<ScenarioConfig> scenario;
};

// Command-line values; a set optional overrides the file.
struct Overrides {
    std::optional<std::string> profile, mode, data_dir, control_socket, log_level, bind;
    std::optional<std::uint16_t> port;
    std::optional<unsigned> node, network;
    std::optional<bool> udp, tcp;
    std::optional<std::size_t> max_connections;
    std::optional<unsigned> tcp_handshake_timeout, tcp_frame_timeout, tcp_idle_timeout,
        tcp_keepalive;
    std::optional<std::size_t> tcp_max_pending;
    std::optional<std::string> network_write_protection;
    std::vector<std::string> protect_nodes;  // non-empty: replaces the file's list
    std::optional<bool> um_read_protection, dip_write_protection;
    std::optional<std::string> durability;
    bool reset_state = false;
    std::vector<std::string> serial;  // --serial NAME=DEVICE[,...], in order
};

using Error = std::string;
template <class T>
using Expected = tl::expected<T, Error>;

// Parses TOML `text` (named `source` in messages) onto `settings`: keys the text does
// not set keep their value. Unknown keys and tables are errors (typos must not pass).
Expected<void> load_config_text(std::string_view text, std::string_view source, Settings& settings);
Expected<void> load_config_file(const std::filesystem::path& file, Settings& settings);
Expected<void> apply_overrides(const Overrides& overrides, Settings& settings);
// Cross-field checks once everything is in: the profile exists, UDP or TCP is on, the
// node list fits the mode, the injections are in range.
Expected<void> validate(const Settings& settings);

// Protections and injections onto the model at start (after the mode is set).
void apply_cpu_options(const CpuUnitOptions& options, plc::Plc& plc);

// [files] `options` against `profile` (a known one): a cassette only where the model has a
// slot, an EM file bank the model has. Errors name `path` ("files", "plc[1].files").
Expected<void> check_file_memory(const server::FileMemoryOptions& options,
                                 const std::string& profile, std::string_view path);

// One [[plc]] table's [protection], [inject], [storage] or [files] (`key`), parsed exactly as the
// single node's onto `cpu`; errors name `path` (e.g. plc[1].protection.network_write).
Expected<void> load_cpu_section(const toml::key& key, const toml::node& node,
                                std::string_view source, const std::string& path, Settings& cpu);

// "program" / "monitor" / "run" (also "stop" for PROGRAM, as on the front panel).
std::optional<plc::OperatingMode> parse_mode(std::string_view text) noexcept;
// "off" / "all" / "listed" / "all-except-listed".
std::optional<plc::NetworkWriteProtection> parse_protection(std::string_view text) noexcept;
// "process" / "power" ([storage] durability).
std::optional<plc::Durability> parse_durability(std::string_view text) noexcept;
// "N.M" or "N.*": network 0-127, node 1-254 or * (any node of the network).
std::optional<NodeAddress> parse_node(std::string_view text) noexcept;

// Checks every [memory] entry against the model (area, range, writable), naming the
// entry on failure. Never writes.
Expected<void> check_initial_memory(const std::vector<MemoryInit>& entries,
                                    const plc::IoMemory& memory);
// True when an entry writes battery-backed memory (H, D, EM, counters, retained A).
bool writes_retained_memory(const MemoryInit& entry) noexcept;
// Writes the entries checked above. With `restored` (the state came from a data
// directory), entries that write retained memory are skipped: initial values never
// overwrite retained data; entries in cleared areas (CIO, W, timers ...) are written
// at every start. Returns how many entries were written.
std::size_t apply_initial_memory(const std::vector<MemoryInit>& entries, plc::IoMemory& memory,
                                 bool restored);

}  // namespace fins::finsd
