// PLC address strings as engineers write them, and their FINS memory addresses.
//
//   D100  D100.15  CIO10.13  10.13  W5  H10.01  A448  T10  C10
//   E3_100  E0_0.05  E100 (current EM bank)  IR0  DR3  TK2  DM100 = D100 (address_names.hpp)
//
// parse_address() accepts these forms (area letters case-insensitive, "CIO" optional
// for a bare number, a bit number with one digit or two: H10.1 = H10.01);
// format_address() prints the canonical form back, bit numbers with two digits as Omron
// writes them (CIO0.00 .. CIO0.15): format(parse(s)) is stable. to_memory_address() picks
// the CS/CJ area code of 5-2-2: a word address the word code, an address with ".bit" the
// bit code; for T/C the word is the PV (89) and Access::bit the completion flag (09).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fins/error.hpp"
#include "fins/memory_area.hpp"

namespace fins {

enum class Area : std::uint8_t {
    cio,
    work,
    holding,
    auxiliary,
    timer,
    counter,
    dm,
    em,          // EM with an explicit bank: E3_100
    em_current,  // EM current bank: E100
    index_register,
    data_register,
    task_flag,
};

struct Address {
    Area area = Area::dm;
    std::uint8_t bank = 0;  // EM bank 0x00-0x18 for Area::em
    std::uint16_t word = 0;
    std::optional<std::uint8_t> bit;  // 0-15 when a bit is named
    friend bool operator==(const Address&, const Address&) = default;
};

// How to access an address on the wire.
enum class Access : std::uint8_t {
    natural,  // the bit code if a bit is named, else the word code
    word,     // word code (bit must be absent)
    bit,      // bit code; for T/C the completion flag, for TK the task flag
    forced,   // with forced status: 70-72 / F0-F2 / 49
};

Result<Address> parse_address(std::string_view text);
std::string format_address(const Address& a);

// Fails with AddressError::bit_not_allowed / bit_required / unknown_area when the
// area has no code for that access (e.g. IR with a bit, EM with forced status).
Result<MemoryAddress> to_memory_address(const Address& a, Access access = Access::natural);

// Largest word number of an area as the 5-2-2 table gives it (CS/CJ mode).
std::uint16_t max_word(Area area) noexcept;

}  // namespace fins
