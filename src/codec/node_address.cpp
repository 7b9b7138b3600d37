#include "fins/node_address.hpp"

#include <algorithm>

namespace fins {

namespace {

std::uint8_t node_from_ipv4(std::span<const std::uint8_t> a) noexcept {
    // 127.0.0.0/8 is loopback (RFC 1122 3.2.1.3): the whole block is node 1.
    return a[0] == 127 ? std::uint8_t{1} : a[3];
}

}  // namespace

std::uint8_t node_from_ip(std::span<const std::uint8_t> address) noexcept {
    if (address.size() == 4) return node_from_ipv4(address);
    if (address.size() != 16) return 0;
    const auto head = address.first(10);
    const bool zero_head = std::all_of(head.begin(), head.end(), [](auto b) { return b == 0; });
    // ::ffff:a.b.c.d (RFC 4291 2.5.5.2) carries an IPv4 address.
    if (zero_head && address[10] == 0xFF && address[11] == 0xFF)
        return node_from_ipv4(address.subspan(12));
    // ::1 is the IPv6 loopback address.
    const auto body = address.first(15);
    if (std::all_of(body.begin(), body.end(), [](auto b) { return b == 0; }) && address[15] == 1)
        return 1;
    return address[15];
}

}  // namespace fins
