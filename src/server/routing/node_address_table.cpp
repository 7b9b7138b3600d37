// NodeAddressTable: the per-method rules of node_address_table.hpp.
#include "server/routing/node_address_table.hpp"

#include "transport/socket_headers.hpp"

#include <cstring>

namespace fins::server {

NodeAddressTable::NodeAddressTable(AddressMethod method, bool dynamic_remote_ip, Ipv4Endpoint own,
                                   const std::vector<IpTableEntry>& table)
    : dynamic_(dynamic_remote_ip) {
    const bool generated = method != AddressMethod::table;
    for (std::size_t n = 1; n < 255; ++n) {
        auto& e = entries_[n];
        e.endpoint.port = own.port;
        if (generated) {
            e.endpoint.ip = own.ip;
            e.endpoint.ip[3] = static_cast<std::uint8_t>(n);
        }
        e.fixed = method == AddressMethod::automatic_static;
    }
    if (method == AddressMethod::table || method == AddressMethod::combined)
        for (const auto& t : table) {
            auto& e = entries_[t.node];
            e.endpoint = Ipv4Endpoint{t.ip, own.port};
            e.fixed = true;
        }
}

std::optional<Ipv4Endpoint> NodeAddressTable::lookup(std::uint8_t node) const noexcept {
    const auto& e = entries_[node];
    if (e.endpoint.ip == std::array<std::uint8_t, 4>{} || e.endpoint.port == 0) return std::nullopt;
    return e.endpoint;
}

void NodeAddressTable::learn(std::uint8_t node, const Ipv4Endpoint& from) noexcept {
    if (!dynamic_ || node == 0 || node == 0xFF) return;
    auto& e = entries_[node];
    if (!e.fixed) e.endpoint = from;
}

std::optional<std::array<std::uint8_t, 4>> parse_ipv4(const std::string& text) noexcept {
    in_addr a{};
    if (::inet_pton(AF_INET, text.c_str(), &a) != 1) return std::nullopt;
    std::array<std::uint8_t, 4> out{};
    std::memcpy(out.data(), &a.s_addr, 4);
    return out;
}

std::uint8_t node_of(const std::array<std::uint8_t, 4>& ip) noexcept {
    return ip[3];
}

}  // namespace fins::server
