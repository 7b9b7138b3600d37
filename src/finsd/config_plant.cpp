// The [[plc]] loader (config_plant.hpp).
#include "finsd/config_plant.hpp"
#include "finsd/config_plant_loader.hpp"

#include <cctype>
#include <chrono>
#include <cstdio>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "finsd/config_schedule.hpp"
#include "finsd/config_serial.hpp"
#include "finsd/config_values.hpp"
#include "plc/profile.hpp"
#include "server/routing/node_address_table.hpp"

namespace fins::finsd {

namespace detail {

using config::Entry;
using config::Key;
using config::Type;
using server::PlantCpuConfig;
using server::PlantPortConfig;

Expected<void> PlantLoader::load(const toml::node& node, const toml::source_region& where,
                                 Settings& settings) {
    const auto* array = node.as_array();
    if (array == nullptr) return fail(where, "plc", "must be an array of tables ([[plc]])");
    for (std::size_t i = 0; i < array->size(); ++i) {
        const auto* table = (*array)[i].as_table();
        const std::string path = fmt::format("plc[{}]", i);
        if (table == nullptr) return fail((*array)[i].source(), path, "must be a table");
        if (const auto* repeat = table->get("repeat")) {
            if (auto r = load_repeated(*table, *repeat, path, settings); !r) return r;
            continue;
        }
        PlantCpuConfig cpu;
        Settings::PlantCpuSettings extra;
        if (auto r = load_cpu(*table, path, cpu, extra); !r) return r;
        settings.plant.cpus.push_back(std::move(cpu));
        settings.plant_cpu.push_back(std::move(extra));
    }
    return {};
}

// A [[plc]] with `repeat = { networks = "20-59", nodes = "1-250" }` is a template:
// one CPU Unit per network and node (networks outer, nodes inner), each loaded from
// the same table with {network}, {node} and {index} (0, 1, ... in that order)
// replaced in its strings (name, bind, data_dir ...), and each [[plc.ethernet]]
// without a network on the repeated network. Errors name the table's position and
// the CPU Unit: "plc[0](20.3).ethernet[0].bind".
Expected<void> PlantLoader::load_repeated(const toml::table& t, const toml::node& repeat,
                                          const std::string& path, Settings& settings) {
    const auto* r = repeat.as_table();
    const std::string rp = path + ".repeat";
    if (r == nullptr)
        return fail(repeat.source(), rp,
                    "must be a table: { networks = \"20-59\", nodes = \"1-250\" }");
    std::optional<std::pair<int, int>> networks, nodes;
    const auto range = [this](std::optional<std::pair<int, int>>& out, int hi) -> config::Reader {
        return [this, &out, hi](const Entry& e) -> Expected<void> {
            auto span = span_of(e.node, e.path, 1, hi);
            if (!span) return tl::unexpected(span.error());
            out = *span;
            return {};
        };
    };
    if (auto read = config::read_table(*r, {source_, rp},
                                       {{"networks", Type::any, range(networks, 127)},
                                        {"nodes", Type::any, range(nodes, 254)}});
        !read)
        return read;
    if (!networks || !nodes) return fail(repeat.source(), rp, "needs networks and nodes");
    // Each CPU Unit needs a name of its own.
    const auto name = t.get_as<std::string>("name");
    if (name != nullptr) {
        const std::string& n = name->get();
        const bool index = n.find("{index}") != std::string::npos;
        const bool node = n.find("{node}") != std::string::npos;
        const bool network = n.find("{network}") != std::string::npos;
        if (!index && !(node && (network || networks->first == networks->second)))
            return fail(name->source(), path + ".name",
                        "with repeat, must contain {index}, or {node} (and {network} "
                        "when several networks repeat)");
    }
    const auto* ethernet = t.get_as<toml::array>("ethernet");
    std::size_t index = 0;
    for (int network = networks->first; network <= networks->second; ++network)
        for (int node = nodes->first; node <= nodes->second; ++node) {
            substitution_ = Substitution{network, node, index++};
            PlantCpuConfig cpu;
            Settings::PlantCpuSettings extra;
            const auto r2 = load_cpu(t, fmt::format("{}({}.{})", path, network, node), cpu, extra);
            substitution_.reset();
            if (!r2) return r2;
            for (std::size_t k = 0; k < cpu.ports.size(); ++k) {
                const auto* e = ethernet != nullptr ? (*ethernet)[k].as_table() : nullptr;
                if (e != nullptr && !e->contains("network"))
                    cpu.ports[k].network = static_cast<std::uint8_t>(network);
            }
            settings.plant.cpus.push_back(std::move(cpu));
            settings.plant_cpu.push_back(std::move(extra));
        }
    return {};
}

// An integer or "FIRST-LAST", within lo-hi.
Expected<std::pair<int, int>> PlantLoader::span_of(const toml::node& v, const std::string& path,
                                                   int lo, int hi) const {
    if (const auto* i = v.as_integer()) {
        if (i->get() < lo || i->get() > hi)
            return fail(v.source(), path, fmt::format("{} is not {}-{}", i->get(), lo, hi));
        return std::pair<int, int>(static_cast<int>(i->get()), static_cast<int>(i->get()));
    }
    const auto* s = v.as_string();
    int first = 0, last = 0;
    char dash = 0, extra = 0;
    if (s == nullptr ||
        std::sscanf(s->get().c_str(), "%d %c %d %c", &first, &dash, &last, &extra) != 3 ||
        dash != '-')
        return fail(v.source(), path, "must be an integer or a range \"FIRST-LAST\"");
    if (first < lo || last > hi || first > last)
        return fail(v.source(), path,
                    fmt::format("{}-{} is not a range within {}-{}", first, last, lo, hi));
    return std::pair<int, int>(first, last);
}

Expected<void> PlantLoader::load_cpu(const toml::table& t, const std::string& path,
                                     PlantCpuConfig& cpu, Settings::PlantCpuSettings& extra) {
    std::optional<toml::source_region> storage_at, files_at;
    // A scratch single node's settings: the top-level loaders read a [[plc]]'s tables.
    const auto single = [this](const Entry& e, Settings& scratch) {
        return load_cpu_section(e.key, e.node, source_, e.path, scratch);
    };
    auto read = config::read_table(
        t, {source_, path},
        {{"repeat"},  // load_repeated's
         text_into("name", cpu.name),
         text_into("profile", cpu.profile),
         {"mode", Type::string,
          [&](const Entry& e) -> Expected<void> {
              const std::string s = substituted(e.text());
              const auto m = parse_mode(s);
              if (!m) return e.fail(fmt::format("'{}' is not program, monitor or run", s));
              cpu.mode = *m;
              return {};
          }},
         {"data_dir", Type::string,
          [&](const Entry& e) -> Expected<void> {
              if (e.text().empty()) return e.fail("must not be empty");
              cpu.data_dir = substituted(e.text());
              return {};
          }},
         {"gateway_count", Type::integer,
          [&](const Entry& e) -> Expected<void> {
              const auto g = e.integer(2, 7);
              if (!g) return tl::unexpected(g.error());
              if (*g != 2 && *g != 7) return e.fail("must be 2 or 7");
              cpu.gateway_count = static_cast<std::uint8_t>(*g);
              return {};
          }},
         {"routing_tables", Type::string,
          [&](const Entry& e) -> Expected<void> {
              const std::string s = substituted(e.text());
              if (s != "config" && s != "keep")
                  return e.fail(fmt::format("'{}' is not config or keep", s));
              cpu.write_routing_tables = s == "config";
              return {};
          }},
         {"ethernet", Type::any,
          [&](const Entry& e) {
              return tables(e.node, e.path, [&](const toml::table& u, const std::string& up) {
                  PlantPortConfig port;
                  if (auto rr = load_port(u, up, port); !rr) return rr;
                  cpu.ports.push_back(std::move(port));
                  extra.port_given.push_back(u.contains("port"));
                  return Expected<void>{};
              });
          }},
         {"memory", Type::any,
          [&](const Entry& e) -> Expected<void> {
              // As the top-level [memory]: entries written in file order.
              const auto* table = e.node.as_table();
              if (table == nullptr) return e.fail("must be a table of ADDRESS = value(s)");
              for (const auto& [ek, ev] : config::in_file_order(*table)) {
                  auto entry = memory_entry(*ek, *ev, source_, e.path);
                  if (!entry) return tl::unexpected(entry.error());
                  extra.memory.push_back(std::move(*entry));
              }
              return {};
          }},
         {"protection", Type::any, [&](const Entry& e) { return cpu_options(e, extra); }},
         {"inject", Type::any, [&](const Entry& e) { return cpu_options(e, extra); }},
         {"storage", Type::any,
          [&](const Entry& e) -> Expected<void> {
              Settings scratch;
              if (auto rr = single(e, scratch); !rr) return rr;
              cpu.durability = scratch.durability;
              storage_at = e.node.source();
              return {};
          }},
         {"files", Type::any,
          [&](const Entry& e) -> Expected<void> {
              // As the top-level [files]: this CPU Unit's card, EM file bank, cassette.
              Settings scratch;
              if (auto rr = single(e, scratch); !rr) return rr;
              cpu.files = static_cast<const server::FileMemoryOptions&>(scratch);
              files_at = e.node.source();
              return {};
          }},
         {"serial", Type::any,
          [&](const Entry& e) -> Expected<void> {
              // As the top-level [serial]: Host Link slave and Serial Gateway ports.
              if (auto rr = load_serial_table(e.node, source_, extra.serial); !rr)
                  return tl::unexpected(in_plant(rr.error(), path));
              return {};
          }},
         {"remote", Type::any, [&](const Entry& e) { return remotes(e, path, cpu, extra); }},
         {"schedule", Type::any, [&](const Entry& e) { return remotes(e, path, cpu, extra); }},
         {"scenario", Type::any,
          [&](const Entry& e) -> Expected<void> {
              auto config = load_scenario_table(e.node, source_, e.path);
              if (!config) return tl::unexpected(config.error());
              extra.scenario = std::move(*config);
              return {};
          }},
         {"relay", Type::any, [&](const Entry& e) {
              return tables(e.node, e.path, [&](const toml::table& u, const std::string& up) {
                  return load_relay(u, up, cpu);
              });
          }}});
    if (!read) return read;
    if (cpu.name.empty()) return fail(t.source(), path, "name: missing");
    if (extra.scenario) extra.scenario->plc = cpu.name;  // reload finds it by name
    if (cpu.durability == plc::Durability::power && !cpu.data_dir)
        return fail(*storage_at, path + ".storage.durability",
                    "\"power\" needs data_dir (without one nothing is kept)");
    // The model's devices, as validate() checks [files] (an unknown profile is
    // validate_plant's to name).
    if (files_at && plc::find_profile(cpu.profile) != nullptr)
        if (auto r = check_file_memory(cpu.files, cpu.profile, path + ".files"); !r)
            return tl::unexpected(fmt::format("{}:{}:{}: {}", source_, files_at->begin.line,
                                              files_at->begin.column, r.error()));
    return check_serial(path, cpu, extra);
}

// A [[plc]]'s [protection] or [inject], parsed as the single node's tables onto a scratch
// Settings.
Expected<void> PlantLoader::cpu_options(const Entry& e, Settings::PlantCpuSettings& extra) {
    Settings scratch;
    static_cast<CpuUnitOptions&>(scratch) = extra;
    if (auto r = load_cpu_section(e.key, e.node, source_, e.path, scratch); !r) return r;
    static_cast<CpuUnitOptions&>(extra) = scratch;
    if (e.key.str() == "protection" &&
        extra.network_write_protection.mode == plc::NetworkWriteProtection::listed &&
        extra.network_write_protection.nodes.empty())
        return e.fail("nodes: empty, so network_write = \"listed\" protects nothing");
    return {};
}

// A [[plc]]'s [[plc.remote]] or [[plc.schedule]], as the top-level ones for this CPU Unit.
Expected<void> PlantLoader::remotes(const Entry& e, const std::string& path, PlantCpuConfig& cpu,
                                    Settings::PlantCpuSettings& extra) {
    Settings scratch;
    auto r = e.key.str() == "remote" ? load_remotes(e.key, e.node, source_, scratch)
                                     : load_schedule(e.key, e.node, source_, scratch);
    if (!r) return tl::unexpected(in_plant(r.error(), path));
    for (auto& remote : scratch.remotes)
        cpu.remotes.push_back(std::move(remote));
    for (auto& entry : scratch.schedule)
        extra.schedule.push_back(std::move(entry));
    return {};
}

// The single node's serial checks, and what a plant adds: a gateway port's network
// is not one of this CPU Unit's Ethernet networks, and a Serial Communications Unit
// does not take the unit number of one of its Ethernet units (a real PLC refuses
// duplicated unit numbers).
Expected<void> PlantLoader::check_serial(const std::string& path, const PlantCpuConfig& cpu,
                                         const Settings::PlantCpuSettings& extra) {
    if (auto r = validate_serial(extra.serial); !r)
        return tl::unexpected(in_plant(r.error(), path));
    for (const auto& s : extra.serial) {
        for (const auto& unit : cpu.ports) {
            if (s.network && *s.network == unit.network)
                return tl::unexpected(
                    fmt::format("{}: {}.serial.{}: network={} is the network of "
                                "[[plc.ethernet]] unit {}",
                                s.where, path, s.name, *s.network, unit.unit_number));
            if (s.kind == SerialPortConfig::Kind::scu && s.unit_number == unit.unit_number)
                return tl::unexpected(
                    fmt::format("{}: {}.serial.{}: unit number {} is the "
                                "[[plc.ethernet]] unit's",
                                s.where, path, s.name, s.unit_number));
        }
    }
    return {};
}

}  // namespace detail

server::PlantPortConfig single_unit(const Settings& s) {
    server::PlantPortConfig unit;
    unit.bind = s.bind;
    unit.port = s.port;
    unit.udp = s.udp;
    unit.tcp = s.tcp;
    unit.node = s.node;
    unit.network = s.network;
    unit.max_connections = s.max_connections;
    return unit;
}

server::TcpLimits tcp_limits(const Settings& s) {
    server::TcpLimits limits;
    limits.handshake_timeout = std::chrono::seconds(s.tcp_handshake_timeout);
    limits.frame_timeout = std::chrono::seconds(s.tcp_frame_timeout);
    limits.idle_timeout = std::chrono::seconds(s.tcp_idle_timeout);
    limits.keepalive = std::chrono::seconds(s.tcp_keepalive);
    limits.max_pending = s.tcp_max_pending;
    return limits;
}

Error in_plant(const Error& error, std::string_view path) {
    // After the position "FILE:L:C: " (FILE may hold colons; L and C are digits).
    std::size_t at = 0;
    for (std::size_t i = error.find(": "); i != std::string::npos; i = error.find(": ", i + 1)) {
        std::size_t j = i, colons = 0;
        while (j > 0 && colons < 2) {
            std::size_t digits = 0;
            while (j > 0 && std::isdigit(static_cast<unsigned char>(error[j - 1])) != 0) {
                --j;
                ++digits;
            }
            if (digits == 0 || j == 0 || error[j - 1] != ':') break;
            --j;
            ++colons;
        }
        if (colons == 2) {
            at = i + 2;
            break;
        }
    }
    // A key path ("serial.cpu", "remote[0].node", "serial:") continues the plant's path;
    // anything else ("serial port cpu") follows it.
    const auto word_end = error.find_first_not_of(
        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_", at);
    const bool key = word_end != std::string::npos && word_end > at &&
                     (error[word_end] == '.' || error[word_end] == '[' || error[word_end] == ':');
    return error.substr(0, at) + std::string(path) + (key ? "." : ": ") + error.substr(at);
}

Expected<void> load_plant(const toml::key& key, const toml::node& node, std::string_view source,
                          Settings& settings) {
    return detail::PlantLoader(source).load(node, key.source(), settings);
}

}  // namespace fins::finsd
