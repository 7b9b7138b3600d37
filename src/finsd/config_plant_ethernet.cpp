// The [[plc.ethernet]] units, their [[plc.ethernet.ip_table]] entries and the
// [[plc.relay]] entries of the [[plc]] loader (config_plant_loader.hpp).
#include <cstdint>
#include <string>

#include <fmt/format.h>

#include "finsd/config_plant_loader.hpp"
#include "server/routing/node_address_table.hpp"

namespace fins::finsd::detail {

using config::Entry;
using config::Type;
using server::AddressMethod;
using server::PlantCpuConfig;
using server::PlantPortConfig;

Expected<void> PlantLoader::load_port(const toml::table& t, const std::string& path,
                                      PlantPortConfig& port) {
    const auto ipv4 = [](const std::string& s) { return server::parse_ipv4(s).has_value(); };
    return config::read_table(
        t, {source_, path},
        {config::integer_key("unit", port.unit_number, 0, 15),
         config::integer_key("network", port.network, 1, 127),
         config::integer_key("node", port.node, 1, 254),
         config::integer_key("port", port.port, 0, 65535),
         config::integer_key("max_connections", port.max_connections, 1, 254),
         {"bind", Type::string,
          [&](const Entry& e) -> Expected<void> {
              const std::string s = substituted(e.text());
              if (!ipv4(s)) return e.fail(fmt::format("'{}' is not an IPv4 address", s));
              port.bind = s;
              return {};
          },
          true},
         config::flag_key("udp", port.udp),
         config::flag_key("tcp", port.tcp),
         config::flag_key("dynamic_remote_ip", port.dynamic_remote_ip),
         {"address_method", Type::string,
          [&](const Entry& e) -> Expected<void> {
              const std::string s = substituted(e.text());
              if (s == "automatic" || s == "automatic-dynamic")
                  port.method = AddressMethod::automatic_dynamic;
              else if (s == "automatic-static")
                  port.method = AddressMethod::automatic_static;
              else if (s == "table")
                  port.method = AddressMethod::table;
              else if (s == "combined")
                  port.method = AddressMethod::combined;
              else
                  return e.fail(
                      fmt::format("'{}' is not automatic, automatic-static, table or combined", s));
              return {};
          }},
         {"ip_table", Type::any, [&](const Entry& e) {
              return tables(e.node, e.path, [&](const toml::table& u, const std::string& up) {
                  return load_ip_entry(u, up, port);
              });
          }}});
}

Expected<void> PlantLoader::load_ip_entry(const toml::table& t, const std::string& path,
                                          PlantPortConfig& port) {
    server::IpTableEntry entry;
    auto r =
        config::read_table(t, {source_, path},
                           {config::integer_key("node", entry.node, 1, 254),
                            {"ip", Type::string, [&](const Entry& e) -> Expected<void> {
                                 const std::string s = substituted(e.text());
                                 const auto a = server::parse_ipv4(s);
                                 if (!a)
                                     return e.fail(fmt::format("'{}' is not an IPv4 address", s));
                                 entry.ip = *a;
                                 return {};
                             }}});
    if (!r) return r;
    if (!t.contains("node") || !t.contains("ip"))
        return fail(t.source(), path, "needs node and ip");
    port.ip_table.push_back(entry);
    return {};
}

Expected<void> PlantLoader::load_relay(const toml::table& t, const std::string& path,
                                       PlantCpuConfig& cpu) {
    plc::RelayNetwork entry;
    auto r = config::read_table(t, {source_, path},
                                {config::integer_key("network", entry.network, 1, 127),
                                 config::integer_key("via_network", entry.relay_network, 1, 127),
                                 config::integer_key("via_node", entry.relay_node, 1, 254)});
    if (!r) return r;
    if (entry.network == 0 || entry.relay_network == 0 || entry.relay_node == 0)
        return fail(t.source(), path, "needs network, via_network and via_node");
    cpu.relays.push_back(entry);
    return {};
}

}  // namespace fins::finsd::detail
