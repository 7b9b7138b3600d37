// The internal node-address table of an Ethernet port (W596 2-3, W420 5-2,
// frames-networks section 4): for every remote node 1-254, the IPv4 address and UDP port
// FINS/UDP frames for it go to. Built at start from the method, changed by received
// frames as the method and the "dynamically change remote IP" option allow:
//
//   method              initial entry for node n            changed by a received frame
//   automatic_dynamic   own network part + n, own port      yes
//   automatic_static    own network part + n, own port      no
//   table               listed: the table's IP, own port    listed: no; others: yes
//                       others: 0.0.0.0 (unknown)
//   combined            listed: the table's IP, own port    listed: no; others: yes
//                       others: own network part + n
// dynamic_remote_ip = false ("Do not convert") keeps every entry as built at start.
// The "network part" is the first three octets (a /24, as on the loopback plant).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace fins::server {

enum class AddressMethod : std::uint8_t { automatic_dynamic, automatic_static, table, combined };

struct IpTableEntry {
    std::uint8_t node = 0;
    std::array<std::uint8_t, 4> ip{};
};

struct Ipv4Endpoint {
    std::array<std::uint8_t, 4> ip{};
    std::uint16_t port = 0;
    friend constexpr bool operator==(const Ipv4Endpoint&, const Ipv4Endpoint&) = default;
};

class NodeAddressTable {
  public:
    NodeAddressTable() = default;
    NodeAddressTable(AddressMethod method, bool dynamic_remote_ip, Ipv4Endpoint own,
                     const std::vector<IpTableEntry>& table);

    // Where frames for `node` go; nullopt when the entry is 0.0.0.0 (unknown).
    [[nodiscard]] std::optional<Ipv4Endpoint> lookup(std::uint8_t node) const noexcept;
    // A FINS frame from `node` arrived from `from`: the entry follows it when the method
    // and option allow.
    void learn(std::uint8_t node, const Ipv4Endpoint& from) noexcept;

  private:
    struct Entry {
        Ipv4Endpoint endpoint;
        bool fixed = false;
    };
    std::array<Entry, 256> entries_{};
    bool dynamic_ = true;
};

// "a.b.c.d" -> its four bytes.
std::optional<std::array<std::uint8_t, 4>> parse_ipv4(const std::string& text) noexcept;
// The node the automatic methods give an address: its last octet.
std::uint8_t node_of(const std::array<std::uint8_t, 4>& ip) noexcept;

}  // namespace fins::server
