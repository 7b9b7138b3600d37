// MEMORY CASSETTE TRANSFER 22 20 (W342 5-3-43; CP1H/CP1L only, 5-1-2). Same command-type
// shape as fins/commands/memory_area.hpp.
//
// The seed gives the fields but no byte diagram (fins-frames "2220", UNCONFIRMED;
// frames-serial-files 4.2). Choices, pinned by tests/codec/commands/memory_cassette_test:
//   command   disk number (2, 8003 Memory Cassette), parameter (2), data type
//             designation (2: it has bits 15 .. 00). The designation is sent with every
//             parameter, also 0003 (initialize) and 8000 (read data type), which ignore it.
//   response  parameter 8000: the stored data type, 2 bytes (bits 15-08 zero), like every
//             other FINS field that numbers bits up to 15; any other parameter: nothing
//             after the end code.
#pragma once

#include <cstdint>
#include <string_view>

#include "fins/byte_io.hpp"
#include "fins/commands/file_memory.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// 5-3-43 "Parameter (command)".
enum class CassetteOperation : std::uint16_t {
    save = 0x0000,        // transfer CPU Unit -> Memory Cassette
    load = 0x0001,        // transfer Memory Cassette -> CPU Unit
    verify = 0x0002,      // compare CPU Unit and Memory Cassette
    initialize = 0x0003,  // erase the Memory Cassette
    read_type = 0x8000,   // which data the Memory Cassette holds
};

// Data type designation (command) bits. Bit 15 OFF: all areas (then bits 00 and 02-07
// must be OFF, else 110C); ON: only the areas of bits 00 and 02-07. Bits 14-08 and 01
// are reserved.
inline constexpr std::uint16_t cassette_individual = 0x8000;
inline constexpr std::uint16_t cassette_dm_initial_values = 0x0080;
inline constexpr std::uint16_t cassette_dm = 0x0040;
inline constexpr std::uint16_t cassette_program_indices = 0x0020;
inline constexpr std::uint16_t cassette_comments = 0x0010;
inline constexpr std::uint16_t cassette_symbol_table = 0x0008;
inline constexpr std::uint16_t cassette_parameters = 0x0004;
inline constexpr std::uint16_t cassette_program = 0x0001;  // user program + FB sources
// The designation bits that name an area (00, 02-07).
inline constexpr std::uint16_t cassette_areas = 0x00FD;
// Stored data type (response) bit 01: function block sources (the designation's bit 01
// is reserved; FB sources travel with the user program, bit 00).
inline constexpr std::uint16_t cassette_fb_sources = 0x0002;

struct MemoryCassetteTransferResponse {
    std::uint16_t stored = 0;  // parameter 8000 only: stored data type bits 07-00
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const MemoryCassetteTransferResponse&,
                           const MemoryCassetteTransferResponse&) = default;
};

struct MemoryCassetteTransfer {
    static constexpr CommandCode code{0x22, 0x20};
    static constexpr std::string_view name = "MEMORY CASSETTE TRANSFER";
    using Response = MemoryCassetteTransferResponse;

    std::uint16_t disk = disk_memory_cassette;
    std::uint16_t operation = static_cast<std::uint16_t>(CassetteOperation::save);
    std::uint16_t designation = 0;  // 0000: all areas

    void encode(ByteWriter& w) const noexcept;
    // 1002 shorter than 6 bytes, 1001 longer; values are the PLC's to judge (110C).
    static Result<MemoryCassetteTransfer> decode(Bytes parameters);
    // Parameter 8000: exactly 2 bytes; otherwise none.
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
