// The routing tables of a CPU Unit (W596 2-4, frames-networks 1.2) and their layout in
// parameter area 8013 (W342 5-3-7..5-3-9: 512 words, 0000-01FF, read and written in
// parts). No public source gives the real word layout (frames-networks 1.3), so finskit
// defines one; docs/networks.md "The 8013 routing-table layout" documents it:
//
//   word 0000         options: bits 0-7 the GCT a frame this CPU Unit starts gets
//                     (00 = 02, 02 or 07 as CX-Net offers); bits 8-15 reserved (00)
//   words 0001-0010   local network table, 16 entries (CX-Net's limit):
//                     bits 8-15 network address 01-7F, bits 0-7 unit number 00-0F
//                     of the Communications Unit on it; 0000 = unused entry
//   words 0011-0038   relay network table, 20 entries of 2 words:
//                     word 1: bits 8-15 destination network 01-7F,
//                             bits 0-7 relay network 01-7F (a local network)
//                     word 2: bits 0-7 relay node 01-FE, bits 8-15 00
//                     0000 0000 = unused entry
//   words 0039-01FF   reserved; kept as written
//
// Binary, as every other network/node/unit number in W342. Every table word 0 (the
// state after 02 03 PARAMETER AREA CLEAR, or a new CPU Unit) means "no routing tables".
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>

namespace fins::plc {

inline constexpr std::uint16_t routing_table_area = 0x8013;
inline constexpr std::size_t max_local_networks = 16;
inline constexpr std::size_t max_relay_networks = 20;
inline constexpr std::size_t local_table_word = 0x0001;
inline constexpr std::size_t relay_table_word = 0x0011;
inline constexpr std::size_t routing_words_used = 0x0039;

struct LocalNetwork {
    std::uint8_t network = 0;  // 01-7F
    std::uint8_t unit = 0;     // unit number 00-0F of the Communications Unit
    friend constexpr bool operator==(const LocalNetwork&, const LocalNetwork&) = default;
};

struct RelayNetwork {
    std::uint8_t network = 0;        // destination ("end") network
    std::uint8_t relay_network = 0;  // a local network
    std::uint8_t relay_node = 0;     // the first relay node on it
    friend constexpr bool operator==(const RelayNetwork&, const RelayNetwork&) = default;
};

struct RoutingTables {
    std::uint8_t gateway_count = 0x02;
    std::array<LocalNetwork, max_local_networks> local{};  // network 0 = unused
    std::array<RelayNetwork, max_relay_networks> relay{};  // network 0 = unused
    std::size_t local_count = 0;
    std::size_t relay_count = 0;

    [[nodiscard]] const LocalNetwork* find_local(std::uint8_t network) const noexcept;
    [[nodiscard]] const RelayNetwork* find_relay(std::uint8_t network) const noexcept;
};

// What the words hold.
enum class RoutingTablesState : std::uint8_t {
    none,    // every table word 0: "no routing tables" (0502)
    valid,   // usable
    broken,  // an entry out of range or contradicting another (0503)
};

struct DecodedRoutingTables {
    RoutingTablesState state = RoutingTablesState::none;
    RoutingTables tables;
};

// Reads the tables from the area's words (at least routing_words_used of them; fewer
// is "none"). Broken: a network 00 with a unit, a network or relay network above 7F,
// a unit number above 0F, a network listed twice, a relay node 00 or FF, a relay
// network that is not in the local table, a destination that is a local network, a
// GCT option other than 00/02/07, a relay entry's second word with its high byte set.
DecodedRoutingTables decode_routing_tables(std::span<const std::uint16_t> words) noexcept;

// Writes `tables` into the first routing_words_used words (the rest is left alone).
void encode_routing_tables(const RoutingTables& tables, std::span<std::uint16_t> words) noexcept;

}  // namespace fins::plc
