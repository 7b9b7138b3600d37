#include "fins/node_address.hpp"

namespace fins {

std::uint8_t node_from_ip(std::span<const std::uint8_t> address) noexcept {
    // One rule for every address, loopback included (node_address.hpp): the last byte is
    // the IPv4 address's last octet, an IPv4-mapped IPv6 address's (::ffff:a.b.c.d, RFC
    // 4291 2.5.5.2) as well, and ::1 gives node 1.
    if (address.size() != 4 && address.size() != 16) return 0;
    return address.back();
}

}  // namespace fins
