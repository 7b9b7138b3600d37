// The FINS node number an IP address implies (frames section 2, "automatic
// generation" of node addresses; W420 5-2): the last octet of an IPv4 address, on
// loopback too (127.0.0.5 is node 5, as a plant's unit bound there is); of an IPv4-mapped
// IPv6 address, its IPv4 address's; of any other IPv6 address (::1 included), its last
// byte.
//
// Pure: the address is given as its network-order bytes (4 for IPv4, 16 for IPv6), so
// the codec needs no socket library. Every end uses it: the client and fins-bridge derive
// their default source and destination nodes, finsd its own node from --bind.
#pragma once

#include <cstdint>
#include <span>

namespace fins {

// Any other length than 4 or 16 bytes yields 0 (no node).
std::uint8_t node_from_ip(std::span<const std::uint8_t> address) noexcept;

}  // namespace fins
