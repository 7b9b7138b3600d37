// Program area access commands 03 06 .. 03 08 (W342 5-3-10 .. 5-3-12, frames 6).
//
// The same command-type shape as fins/commands/memory_area.hpp. The program area (UM)
// is addressed in bytes from 00000000; addresses and byte counts are multiples of 4.
// Byte counts carry bit 15 like the parameter-area word counts: in a read response
// "the data at the last address in the program area is included", in a write "program
// area writing is completed" (the last block of a download).
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// 5-3-10..5-3-12: the program number is always FFFF (else 1106 program missing).
inline constexpr std::uint16_t program_number_all = 0xFFFF;
// 5-3-10: at most 992 bytes per read; 5-3-11: at most 996 bytes per write.
inline constexpr std::uint16_t max_program_read_bytes = 992;
inline constexpr std::uint16_t max_program_write_bytes = 996;
// 5-3-10 / 5-3-11: addresses and byte counts are multiples of four.
inline constexpr std::uint32_t program_alignment = 4;
inline constexpr std::uint16_t program_last_bit = 0x8000;
inline constexpr std::uint16_t program_count_mask = 0x7FFF;

// 5-3-12 clear codes.
inline constexpr std::uint8_t clear_without_interrupt_tasks = 0x00;
inline constexpr std::uint8_t clear_with_interrupt_tasks = 0x10;

struct ProgramAreaReadResponse {
    std::uint16_t program_number = program_number_all;
    std::uint32_t address = 0;
    std::uint16_t count = 0;  // bytes returned (bits 0-14)
    bool last = false;        // bit 15: the program area's last address is included
    std::vector<std::uint8_t> data;
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const ProgramAreaReadResponse&,
                           const ProgramAreaReadResponse&) = default;
};

struct ProgramAreaRead {
    static constexpr CommandCode code{0x03, 0x06};
    static constexpr std::string_view name = "PROGRAM AREA READ";
    using Response = ProgramAreaReadResponse;

    std::uint16_t program_number = program_number_all;
    std::uint32_t address = 0;  // byte address, multiple of 4
    std::uint16_t count = 0;    // bytes (bits 0-14), multiple of 4, at most 992
    bool last = false;          // bit 15: must be 0 in a command (the handler answers 110C)

    void encode(ByteWriter& w) const noexcept;
    // 1002 when shorter than 8 bytes, 1001 when longer.
    static Result<ProgramAreaRead> decode(Bytes parameters) noexcept;
    // Echoed program number and address, at most `count` bytes, data = returned count.
    Result<Response> decode_response(Bytes data) const;
};

struct ProgramAreaWriteResponse {
    std::uint16_t program_number = program_number_all;
    std::uint32_t address = 0;
    std::uint16_t count = 0;
    bool last = false;
    void encode(ByteWriter& w) const noexcept;
    friend bool operator==(const ProgramAreaWriteResponse&,
                           const ProgramAreaWriteResponse&) = default;
};

struct ProgramAreaWrite {
    static constexpr CommandCode code{0x03, 0x07};
    static constexpr std::string_view name = "PROGRAM AREA WRITE";
    using Response = ProgramAreaWriteResponse;

    std::uint16_t program_number = program_number_all;
    std::uint32_t address = 0;  // byte address, multiple of 4
    std::uint16_t count = 0;    // bytes (bits 0-14), multiple of 4, at most 996
    bool last = false;          // bit 15: the last block of the program
    Bytes data;                 // count bytes; a view, the caller keeps it alive

    void encode(ByteWriter& w) const noexcept;
    // 1002 when shorter than 8 bytes; the data length is checked by the handler (1003).
    static Result<ProgramAreaWrite> decode(Bytes parameters) noexcept;
    // The response echoes program number, address and byte count (5-3-11).
    Result<Response> decode_response(Bytes data) const;
};

struct ProgramAreaClear {
    static constexpr CommandCode code{0x03, 0x08};
    static constexpr std::string_view name = "PROGRAM AREA CLEAR";
    using Response = EmptyResponse;

    std::uint16_t program_number = program_number_all;
    std::uint8_t clear_code = clear_without_interrupt_tasks;  // 00 or 10

    void encode(ByteWriter& w) const noexcept;
    // 1002 when shorter than 3 bytes, 1001 when longer.
    static Result<ProgramAreaClear> decode(Bytes parameters) noexcept;
    Result<Response> decode_response(Bytes data) const;
};

}  // namespace fins
