// Parameter area access commands 02 01 .. 02 03 (W342 5-3-7 .. 5-3-9, frames 6).
//
// The same command-type shape as fins/commands/memory_area.hpp. Word counts carry two
// things on the wire: bits 0-14 the number of words, bit 15 the "last word" flag
// (5-3-7: set in a read response that holds the area's last word; 5-3-8: must be set
// on the write that holds the area's last word). The structs keep them apart:
// `count` (0-0x7FFF) and `last_word`.
//
// The parameter areas and their sizes (5-3-7 "Parameter Areas") are data here, shared
// by the client, the CLI and the virtual PLC. Code 8000 addresses all areas as one
// range 0000-1F3F (8,000 words). The manual lists the four areas (7,488 words) and the
// 8,000-word total but not the order inside 8000; finskit lays them out by ascending
// sub-code with the CV-series code 8011 as a 512-word reserved block (which makes the
// sizes add up exactly):
//   0000-01FF 8010 PLC Setup        0200-03FF reserved (8011, not addressable alone)
//   0400-08FF 8012 I/O table        0900-0AFF 8013 routing tables
//   0B00-1F3F 8002 CPU Bus Unit setup
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// W342 5-3-7 / 5-3-8: at most 498 words per read or write.
inline constexpr std::uint16_t max_parameter_words = 498;
// Bit 15 of a number-of-words (or number-of-bytes) field.
inline constexpr std::uint16_t last_word_bit = 0x8000;
inline constexpr std::uint16_t word_count_mask = 0x7FFF;

struct ParameterAreaInfo {
    std::uint16_t code = 0;    // 8010 ...
    std::string_view id;       // CLI name: "plc-setup", "io-table", "routing", "cpu-bus", "all"
    std::string_view name;     // the manual's name
    std::uint16_t words = 0;   // size (5-3-7 table)
    std::uint16_t offset = 0;  // first word inside area 8000 (layout above)
    bool whole_area = true;    // 5-3-7: "Except for the routing table area, each area must
                               // be read or written in its entirety"
};

inline constexpr std::uint16_t parameter_area_all = 0x8000;
inline constexpr std::uint16_t parameter_area_cpu_bus_unit_setup = 0x8002;
inline constexpr std::uint16_t parameter_area_plc_setup = 0x8010;
inline constexpr std::uint16_t parameter_area_io_table = 0x8012;
inline constexpr std::uint16_t parameter_area_routing_tables = 0x8013;
// Size of the 8000 range: 0000-1F3F.
inline constexpr std::uint16_t parameter_area_all_words = 8000;

// The five codes of 5-3-7, ascending by code.
std::span<const ParameterAreaInfo> parameter_area_table() noexcept;
// nullptr for a code the table does not list (the CPU Unit answers 1101).
const ParameterAreaInfo* find_parameter_area(std::uint16_t code) noexcept;
// By CLI id ("plc-setup") or by code in hex ("8010", "0x8010"); nullptr if neither.
const ParameterAreaInfo* find_parameter_area(std::string_view id_or_code) noexcept;

struct ParameterAreaReadResponse {
    std::uint16_t area = 0;
    std::uint16_t start = 0;
    std::uint16_t count = 0;  // words returned (bits 0-14)
    bool last_word = false;   // bit 15: the area's last word is included
    std::vector<std::uint16_t> words;
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const ParameterAreaReadResponse&,
                           const ParameterAreaReadResponse&) = default;
};

struct ParameterAreaRead {
    static constexpr CommandCode code{0x02, 0x01};
    static constexpr std::string_view name = "PARAMETER AREA READ";
    using Response = ParameterAreaReadResponse;

    std::uint16_t area = 0;
    std::uint16_t start = 0;  // relative word address, 0000 = start of the area
    std::uint16_t count = 0;  // bits 0-14
    bool last_word = false;   // bit 15: must be 0 in a command (the handler answers 110C)

    void encode(ByteWriter& w) const noexcept;
    // 1002 when shorter than 6 bytes, 1001 when longer.
    static Result<ParameterAreaRead> decode(Bytes parameters) noexcept;
    // Echoed area and start, at most `count` words, data exactly 2 x returned count.
    Result<Response> decode_response(Bytes data) const;
};

struct ParameterAreaWrite {
    static constexpr CommandCode code{0x02, 0x02};
    static constexpr std::string_view name = "PARAMETER AREA WRITE";
    using Response = EmptyResponse;

    std::uint16_t area = 0;
    std::uint16_t start = 0;
    std::uint16_t count = 0;  // bits 0-14
    bool last_word = false;   // bit 15: this write holds the area's last word
    Bytes data;               // 2 x count bytes; a view, the caller keeps it alive

    void encode(ByteWriter& w) const noexcept;
    // 1002 when shorter than 6 bytes. The data length is checked by the handler, after
    // the area and range (1101/1103/1104 come before 1003, as for 01 02).
    static Result<ParameterAreaWrite> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

struct ParameterAreaClear {
    static constexpr CommandCode code{0x02, 0x03};
    static constexpr std::string_view name = "PARAMETER AREA CLEAR";
    using Response = EmptyResponse;

    std::uint16_t area = 0;
    std::uint16_t start = 0;  // always 0000 (5-3-9)
    std::uint16_t count = 0;  // bits 0-14: the whole area, or 0 for "nothing"
    bool last_word = false;   // bit 15: accepted either way (the whole area is the last word)
    std::uint16_t value = 0;  // clear data: always 0000 (5-3-9)

    void encode(ByteWriter& w) const noexcept;
    // 1002 when shorter than 8 bytes, 1001 when longer.
    static Result<ParameterAreaClear> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
