// The FINS node number an IP address implies (frames section 2, "automatic
// generation" of node addresses): loopback -> 1; IPv4 (or IPv4-mapped IPv6) -> the last
// octet; any other IPv6 address -> its last byte.
//
// Pure: the address is given as its network-order bytes (4 for IPv4, 16 for IPv6), so
// the codec needs no socket library. Both ends use it: the client derives its default
// source and destination nodes, finsd its own node from --bind.
#pragma once

#include <cstdint>
#include <span>

namespace fins {

// Any other length than 4 or 16 bytes yields 0 (no node).
std::uint8_t node_from_ip(std::span<const std::uint8_t> address) noexcept;

}  // namespace fins
