// Modbus-RTU and Modbus-ASCII framing, the serial side of 28 04 and 28 05 (W342 5-3-47,
// 5-3-48; frames-serial-files.md 2.1; Modbus over Serial Line v1.02 2.5). Pure.
//
//   RTU:   address (1) | function (1) | data (n) | CRC-16 (2, low byte first)
//          frames are delimited by a silent interval of 3.5 characters
//   ASCII: ':' | address function data as hex digits | LRC (2 hex digits) | CR LF
// An exception response sets bit 7 of the function code and carries one exception code.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include "fins/byte_io.hpp"

namespace fins::modbus {

// Modbus over Serial Line 2.5.1.1: an RTU frame is at most 256 bytes; an ASCII frame at
// most 513 characters (2.5.2.1).
inline constexpr std::size_t max_rtu_frame = 256;
inline constexpr std::size_t max_ascii_frame = 513;
inline constexpr std::uint8_t exception_bit = 0x80;

// CRC-16/MODBUS (polynomial A001 reflected, initial FFFF).
std::uint16_t crc16(Bytes bytes) noexcept;
// Two's complement of the 8-bit sum of the bytes.
std::uint8_t lrc(Bytes bytes) noexcept;

// address + function + data, then the CRC low byte first.
void write_rtu_frame(ByteWriter& w, Bytes pdu) noexcept;
// True when `frame` (with its CRC) is at least address + function + CRC and the CRC
// matches.
bool rtu_crc_ok(Bytes frame) noexcept;

// How long the RTU response to a request with function `function` is, judged from the
// bytes received so far: the length once it is known, nothing while it cannot be known
// yet (or never: an unknown function code; the silent interval then ends the frame).
// Covers the public functions 01-06, 0F, 10, 16, 17 and every exception response.
std::optional<std::size_t> rtu_response_size(Bytes received) noexcept;

// ':' + `ascii` (the address, function and data as hex digits) + LRC + CR LF. Returns
// false (and writes nothing) when `ascii` is not an even number of hex digits.
bool write_ascii_frame(ByteWriter& w, Bytes ascii) noexcept;

struct AsciiParse {
    enum class Status : std::uint8_t {
        need_more,     // no CR LF after a ':' yet (bytes before ':' are skipped)
        complete,      // `ascii` holds the hex digits before the LRC
        bad_checksum,  // the LRC does not match
        malformed,     // odd length, a non-hex digit, or too long
    };
    Status status = Status::need_more;
    std::size_t consumed = 0;
    Bytes ascii;  // between ':' and the LRC
};
AsciiParse parse_ascii_frame(Bytes stream) noexcept;

// Hex digits <-> bytes ("0103" <-> 01 03); decode gives nothing on a bad digit or odd
// length, or when `out` is too small. Upper-case digits are written.
std::optional<std::size_t> hex_decode(Bytes ascii, MutableBytes out) noexcept;
void hex_encode(ByteWriter& w, Bytes binary) noexcept;

}  // namespace fins::modbus
