// The [[plc.ethernet]] units, their [[plc.ethernet.ip_table]] entries and the
// [[plc.relay]] entries of the [[plc]] loader (config_plant_loader.hpp).
#include <cstdint>
#include <string>

#include <fmt/format.h>

#include "finsd/config_plant_loader.hpp"
#include "server/routing/node_address_table.hpp"

namespace fins::finsd::detail {

using server::AddressMethod;
using server::PlantCpuConfig;
using server::PlantPortConfig;

Expected<void> PlantLoader::load_port(const toml::table& t, const std::string& path,
                                      PlantPortConfig& port) {
    bool has_bind = false;
    for (auto&& [k, v] : t) {
        const std::string key(k.str());
        const std::string p = path + "." + key;
        if (key == "unit" || key == "network" || key == "node" || key == "port" ||
            key == "max_connections") {
            const std::int64_t lo = key == "network" || key == "node" || key == "max_connections";
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

Expected<void> PlantLoader::load_ip_entry(const toml::table& t, const std::string& path,
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

Expected<void> PlantLoader::load_relay(const toml::table& t, const std::string& path,
                                       PlantCpuConfig& cpu) {
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

}  // namespace fins::finsd::detail
