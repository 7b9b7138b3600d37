// The 8013 word layout of the routing tables (see routing_tables.hpp).
#include "plc/routing_tables.hpp"

#include <algorithm>

namespace fins::plc {

namespace {

constexpr std::uint8_t max_network = 0x7F;
constexpr std::uint8_t max_unit_number = 0x0F;

constexpr std::uint8_t high(std::uint16_t w) noexcept {
    return static_cast<std::uint8_t>(w >> 8);
}
constexpr std::uint8_t low(std::uint16_t w) noexcept {
    return static_cast<std::uint8_t>(w & 0xFF);
}
constexpr std::uint16_t word(std::uint8_t hi, std::uint8_t lo) noexcept {
    return static_cast<std::uint16_t>((hi << 8) | lo);
}

}  // namespace

const LocalNetwork* RoutingTables::find_local(std::uint8_t network) const noexcept {
    for (std::size_t i = 0; i < local_count; ++i)
        if (local[i].network == network) return &local[i];
    return nullptr;
}

const RelayNetwork* RoutingTables::find_relay(std::uint8_t network) const noexcept {
    for (std::size_t i = 0; i < relay_count; ++i)
        if (relay[i].network == network) return &relay[i];
    return nullptr;
}

DecodedRoutingTables decode_routing_tables(std::span<const std::uint16_t> words) noexcept {
    DecodedRoutingTables out;
    if (words.size() < routing_words_used) return out;
    const auto used = words.first(routing_words_used);
    const auto tables = used.subspan(local_table_word);
    if (std::all_of(tables.begin(), tables.end(), [](std::uint16_t w) { return w == 0; }))
        return out;
    out.state = RoutingTablesState::broken;
    RoutingTables& t = out.tables;

    const auto options = used[0];
    if (high(options) != 0) return out;
    if (low(options) == 0 || low(options) == 0x02)
        t.gateway_count = 0x02;
    else if (low(options) == 0x07)
        t.gateway_count = 0x07;
    else
        return out;

    for (std::size_t i = 0; i < max_local_networks; ++i) {
        const auto w = used[local_table_word + i];
        if (w == 0) continue;
        const LocalNetwork entry{high(w), low(w)};
        if (entry.network == 0 || entry.network > max_network || entry.unit > max_unit_number ||
            t.find_local(entry.network) != nullptr)
            return out;
        t.local[t.local_count++] = entry;
    }
    for (std::size_t i = 0; i < max_relay_networks; ++i) {
        const auto w1 = used[relay_table_word + 2 * i];
        const auto w2 = used[relay_table_word + 2 * i + 1];
        if (w1 == 0 && w2 == 0) continue;
        const RelayNetwork entry{high(w1), low(w1), low(w2)};
        if (high(w2) != 0 || entry.network == 0 || entry.network > max_network ||
            entry.relay_network == 0 || entry.relay_network > max_network ||
            entry.relay_node == 0 || entry.relay_node == 0xFF ||
            t.find_local(entry.relay_network) == nullptr ||
            t.find_local(entry.network) != nullptr || t.find_relay(entry.network) != nullptr)
            return out;
        t.relay[t.relay_count++] = entry;
    }
    out.state = RoutingTablesState::valid;
    return out;
}

void encode_routing_tables(const RoutingTables& tables, std::span<std::uint16_t> words) noexcept {
    if (words.size() < routing_words_used) return;
    std::fill_n(words.begin(), routing_words_used, std::uint16_t{0});
    words[0] = tables.gateway_count == 0x07 ? 0x0007 : 0x0002;
    for (std::size_t i = 0; i < tables.local_count && i < max_local_networks; ++i)
        words[local_table_word + i] = word(tables.local[i].network, tables.local[i].unit);
    for (std::size_t i = 0; i < tables.relay_count && i < max_relay_networks; ++i) {
        const auto& e = tables.relay[i];
        words[relay_table_word + 2 * i] = word(e.network, e.relay_network);
        words[relay_table_word + 2 * i + 1] = e.relay_node;
    }
}

}  // namespace fins::plc
