// The [[plc]] loader (config_plant.hpp).
#include "cli/finsd/config_plant.hpp"

#include <cctype>
#include <chrono>
#include <cstdio>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "cli/finsd/config_schedule.hpp"
#include "cli/finsd/config_serial.hpp"
#include "cli/finsd/config_values.hpp"
#include "plc/profile.hpp"
#include "server/routing/node_address_table.hpp"

namespace fins::cli::finsd {

namespace {

using server::AddressMethod;
using server::PlantCpuConfig;
using server::PlantPortConfig;

class PlantLoader {
  public:
    explicit PlantLoader(std::string_view source) : source_(source) {}

    Expected<void> load(const toml::node& node, const toml::source_region& where,
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

  private:
    // A [[plc]] with `repeat = { networks = "20-59", nodes = "1-250" }` is a template:
    // one CPU Unit per network and node (networks outer, nodes inner), each loaded from
    // the same table with {network}, {node} and {index} (0, 1, ... in that order)
    // replaced in its strings (name, bind, data_dir ...), and each [[plc.ethernet]]
    // without a network on the repeated network. Errors name the table's position and
    // the CPU Unit: "plc[0](20.3).ethernet[0].bind".
    Expected<void> load_repeated(const toml::table& t, const toml::node& repeat,
                                 const std::string& path, Settings& settings) {
        const auto* r = repeat.as_table();
        const std::string rp = path + ".repeat";
        if (r == nullptr)
            return fail(repeat.source(), rp,
                        "must be a table: { networks = \"20-59\", nodes = \"1-250\" }");
        std::optional<std::pair<int, int>> networks, nodes;
        for (auto&& [k, v] : *r) {
            const std::string key(k.str());
            const std::string p = rp + "." + key;
            if (key != "networks" && key != "nodes") return fail(k.source(), p, "unknown key");
            auto range = span_of(v, p, 1, key == "networks" ? 127 : 254);
            if (!range) return tl::unexpected(range.error());
            (key == "networks" ? networks : nodes) = *range;
        }
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
                const auto r2 =
                    load_cpu(t, fmt::format("{}({}.{})", path, network, node), cpu, extra);
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
    Expected<std::pair<int, int>> span_of(const toml::node& v, const std::string& path, int lo,
                                          int hi) const {
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

    // The placeholders of the CPU Unit a repeated [[plc]] is being loaded for.
    struct Substitution {
        int network;
        int node;
        std::size_t index;
    };
    std::string substituted(std::string s) const {
        if (!substitution_) return s;
        const auto replace = [&s](std::string_view name, const std::string& value) {
            for (auto at = s.find(name); at != std::string::npos; at = s.find(name, at)) {
                s.replace(at, name.size(), value);
                at += value.size();
            }
        };
        replace("{network}", std::to_string(substitution_->network));
        replace("{node}", std::to_string(substitution_->node));
        replace("{index}", std::to_string(substitution_->index));
        return s;
    }
    std::optional<Substitution> substitution_;

    tl::unexpected<Error> fail(const toml::source_region& where, std::string_view path,
                               std::string_view message) const {
        return tl::unexpected<Error>(fmt::format("{}:{}:{}: {}: {}", source_, where.begin.line,
                                                 where.begin.column, path, message));
    }

    Expected<std::int64_t> integer(const toml::node& v, const std::string& path, std::int64_t lo,
                                   std::int64_t hi) const {
        const auto* i = v.as_integer();
        if (i == nullptr) return fail(v.source(), path, "must be an integer");
        if (i->get() < lo || i->get() > hi)
            return fail(v.source(), path, fmt::format("{} is not {}-{}", i->get(), lo, hi));
        return i->get();
    }
    Expected<std::string> text(const toml::node& v, const std::string& path) const {
        const auto* s = v.as_string();
        if (s == nullptr) return fail(v.source(), path, "must be a string");
        return substituted(s->get());
    }
    Expected<bool> flag(const toml::node& v, const std::string& path) const {
        const auto* b = v.as_boolean();
        if (b == nullptr) return fail(v.source(), path, "must be true or false");
        return b->get();
    }
    template <class F>
    Expected<void> tables(const toml::node& v, const std::string& path, F&& each) const {
        const auto* array = v.as_array();
        if (array == nullptr) return fail(v.source(), path, "must be an array of tables");
        for (std::size_t i = 0; i < array->size(); ++i) {
            const auto* t = (*array)[i].as_table();
            const std::string child = fmt::format("{}[{}]", path, i);
            if (t == nullptr) return fail((*array)[i].source(), child, "must be a table");
            if (auto r = each(*t, child); !r) return r;
        }
        return {};
    }

    Expected<void> load_cpu(const toml::table& t, const std::string& path, PlantCpuConfig& cpu,
                            Settings::PlantCpuSettings& extra) {
        std::optional<toml::source_region> storage_at, files_at;
        for (auto&& [k, v] : t) {
            const std::string key(k.str());
            if (key == "repeat") continue;  // load_repeated's
            const std::string p = path + "." + key;
            Expected<void> r;
            if (key == "name") {
                auto s = text(v, p);
                if (!s) return tl::unexpected(s.error());
                cpu.name = *s;
            } else if (key == "profile") {
                auto s = text(v, p);
                if (!s) return tl::unexpected(s.error());
                cpu.profile = *s;
            } else if (key == "mode") {
                auto s = text(v, p);
                if (!s) return tl::unexpected(s.error());
                const auto m = parse_mode(*s);
                if (!m)
                    return fail(v.source(), p,
                                fmt::format("'{}' is not program, monitor or run", *s));
                cpu.mode = *m;
            } else if (key == "data_dir") {
                auto s = text(v, p);
                if (!s) return tl::unexpected(s.error());
                if (s->empty()) return fail(v.source(), p, "must not be empty");
                cpu.data_dir = *s;
            } else if (key == "gateway_count") {
                auto g = integer(v, p, 2, 7);
                if (!g) return tl::unexpected(g.error());
                if (*g != 2 && *g != 7) return fail(v.source(), p, "must be 2 or 7");
                cpu.gateway_count = static_cast<std::uint8_t>(*g);
            } else if (key == "routing_tables") {
                auto s = text(v, p);
                if (!s) return tl::unexpected(s.error());
                if (*s != "config" && *s != "keep")
                    return fail(v.source(), p, fmt::format("'{}' is not config or keep", *s));
                cpu.write_routing_tables = *s == "config";
            } else if (key == "ethernet") {
                r = tables(v, p, [&](const toml::table& e, const std::string& ep) {
                    PlantPortConfig port;
                    if (auto rr = load_port(e, ep, port); !rr) return rr;
                    cpu.ports.push_back(std::move(port));
                    extra.port_given.push_back(e.contains("port"));
                    return Expected<void>{};
                });
            } else if (key == "memory") {
                // As the top-level [memory]: entries written in file order.
                const auto* table = v.as_table();
                if (table == nullptr)
                    return fail(v.source(), p, "must be a table of ADDRESS = value(s)");
                for (const auto& [ek, ev] : in_file_order(*table)) {
                    auto entry = memory_entry(*ek, *ev, source_, p);
                    if (!entry) return tl::unexpected(entry.error());
                    extra.memory.push_back(std::move(*entry));
                }
            } else if (key == "protection" || key == "inject") {
                // Parsed as the single node's tables, onto a scratch Settings.
                Settings scratch;
                static_cast<CpuUnitOptions&>(scratch) = extra;
                if (auto rr = load_cpu_section(k, v, source_, p, scratch); !rr) return rr;
                static_cast<CpuUnitOptions&>(extra) = scratch;
                if (key == "protection" &&
                    extra.network_write_protection.mode == plc::NetworkWriteProtection::listed &&
                    extra.network_write_protection.nodes.empty())
                    return fail(v.source(), p,
                                "nodes: empty, so network_write = \"listed\" protects nothing");
            } else if (key == "storage") {
                Settings scratch;
                if (auto rr = load_cpu_section(k, v, source_, p, scratch); !rr) return rr;
                cpu.durability = scratch.durability;
                storage_at = v.source();
            } else if (key == "files") {
                // As the top-level [files]: this CPU Unit's card, EM file bank, cassette.
                Settings scratch;
                if (auto rr = load_cpu_section(k, v, source_, p, scratch); !rr) return rr;
                cpu.files = static_cast<const server::FileMemoryOptions&>(scratch);
                files_at = v.source();
            } else if (key == "serial") {
                // As the top-level [serial]: Host Link slave and Serial Gateway ports.
                if (auto rr = load_serial_table(v, source_, extra.serial); !rr)
                    return tl::unexpected(in_plant(rr.error(), path));
            } else if (key == "remote" || key == "schedule") {
                // As the top-level [[remote]] / [[schedule]], for this CPU Unit.
                Settings scratch;
                auto rr = key == "remote" ? load_remotes(k, v, source_, scratch)
                                          : load_schedule(k, v, source_, scratch);
                if (!rr) return tl::unexpected(in_plant(rr.error(), path));
                for (auto& remote : scratch.remotes)
                    cpu.remotes.push_back(std::move(remote));
                for (auto& entry : scratch.schedule)
                    extra.schedule.push_back(std::move(entry));
            } else if (key == "scenario") {
                auto config = load_scenario_table(v, source_, p);
                if (!config) return tl::unexpected(config.error());
                extra.scenario = std::move(*config);
            } else if (key == "relay") {
                r = tables(v, p, [&](const toml::table& e, const std::string& ep) {
                    return load_relay(e, ep, cpu);
                });
            } else {
                return fail(k.source(), p, "unknown key");
            }
            if (!r) return r;
        }
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

    // The single node's serial checks, and what a plant adds: a gateway port's network
    // is not one of this CPU Unit's Ethernet networks, and a Serial Communications Unit
    // does not take the unit number of one of its Ethernet units (a real PLC refuses
    // duplicated unit numbers).
    static Expected<void> check_serial(const std::string& path, const PlantCpuConfig& cpu,
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

    Expected<void> load_port(const toml::table& t, const std::string& path, PlantPortConfig& port) {
        bool has_bind = false;
        for (auto&& [k, v] : t) {
            const std::string key(k.str());
            const std::string p = path + "." + key;
            if (key == "unit" || key == "network" || key == "node" || key == "port" ||
                key == "max_connections") {
                const std::int64_t lo =
                    key == "network" || key == "node" || key == "max_connections";
                const std::int64_t hi = key == "unit"      ? 15
                                        : key == "network" ? 127
                                        : key == "node"    ? 254
                                        : key == "port"    ? 65535
                                                           : 254;
                auto i = integer(v, p, lo, hi);
                if (!i) return tl::unexpected(i.error());
                if (key == "unit") port.unit_number = static_cast<std::uint8_t>(*i);
                if (key == "network") port.network = static_cast<std::uint8_t>(*i);
                if (key == "node") port.node = static_cast<std::uint8_t>(*i);
                if (key == "port") port.port = static_cast<std::uint16_t>(*i);
                if (key == "max_connections") port.max_connections = static_cast<std::size_t>(*i);
            } else if (key == "bind") {
                auto s = text(v, p);
                if (!s) return tl::unexpected(s.error());
                if (!server::parse_ipv4(*s))
                    return fail(v.source(), p, fmt::format("'{}' is not an IPv4 address", *s));
                port.bind = *s;
                has_bind = true;
            } else if (key == "udp" || key == "tcp" || key == "dynamic_remote_ip") {
                auto b = flag(v, p);
                if (!b) return tl::unexpected(b.error());
                (key == "udp" ? port.udp : key == "tcp" ? port.tcp : port.dynamic_remote_ip) = *b;
            } else if (key == "address_method") {
                auto s = text(v, p);
                if (!s) return tl::unexpected(s.error());
                if (*s == "automatic" || *s == "automatic-dynamic")
                    port.method = AddressMethod::automatic_dynamic;
                else if (*s == "automatic-static")
                    port.method = AddressMethod::automatic_static;
                else if (*s == "table")
                    port.method = AddressMethod::table;
                else if (*s == "combined")
                    port.method = AddressMethod::combined;
                else
                    return fail(v.source(), p,
                                fmt::format("'{}' is not automatic, automatic-static, table or "
                                            "combined",
                                            *s));
            } else if (key == "ip_table") {
                auto r = tables(v, p, [&](const toml::table& e, const std::string& ep) {
                    return load_ip_entry(e, ep, port);
                });
                if (!r) return r;
            } else {
                return fail(k.source(), p, "unknown key");
            }
        }
        if (!has_bind) return fail(t.source(), path, "bind: missing");
        return {};
    }

    Expected<void> load_ip_entry(const toml::table& t, const std::string& path,
                                 PlantPortConfig& port) {
        server::IpTableEntry entry;
        bool node = false, ip = false;
        for (auto&& [k, v] : t) {
            const std::string key(k.str());
            const std::string p = path + "." + key;
            if (key == "node") {
                auto i = integer(v, p, 1, 254);
                if (!i) return tl::unexpected(i.error());
                entry.node = static_cast<std::uint8_t>(*i);
                node = true;
            } else if (key == "ip") {
                auto s = text(v, p);
                if (!s) return tl::unexpected(s.error());
                const auto a = server::parse_ipv4(*s);
                if (!a) return fail(v.source(), p, fmt::format("'{}' is not an IPv4 address", *s));
                entry.ip = *a;
                ip = true;
            } else {
                return fail(k.source(), p, "unknown key");
            }
        }
        if (!node || !ip) return fail(t.source(), path, "needs node and ip");
        port.ip_table.push_back(entry);
        return {};
    }

    Expected<void> load_relay(const toml::table& t, const std::string& path, PlantCpuConfig& cpu) {
        plc::RelayNetwork entry;
        for (auto&& [k, v] : t) {
            const std::string key(k.str());
            const std::string p = path + "." + key;
            const bool node = key == "via_node";
            if (key != "network" && key != "via_network" && !node)
                return fail(k.source(), p, "unknown key");
            auto i = integer(v, p, 1, node ? 254 : 127);
            if (!i) return tl::unexpected(i.error());
            const auto value = static_cast<std::uint8_t>(*i);
            if (key == "network") entry.network = value;
            if (key == "via_network") entry.relay_network = value;
            if (node) entry.relay_node = value;
        }
        if (entry.network == 0 || entry.relay_network == 0 || entry.relay_node == 0)
            return fail(t.source(), path, "needs network, via_network and via_node");
        cpu.relays.push_back(entry);
        return {};
    }

    std::string_view source_;
};

}  // namespace

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
    return PlantLoader(source).load(node, key.source(), settings);
}

}  // namespace fins::cli::finsd
