// CompoWay/F framing (Omron components: temperature controllers, panel meters ...), the
// serial side of 28 03 CONVERT TO COMPOWAY/F COMMAND (W342 5-3-46; frames-serial-files.md
// section 1). Pure: bytes in, views and enums out, no I/O.
//
//   command:  STX | node (2) | sub-address (2) | SID (1) | MRC SRC (4) | text | ETX | BCC
//   response: STX | node (2) | sub-address (2) | end code (2) | [MRC SRC (4) | MRES SRES (4)
//             | text] | ETX | BCC
// All fields between STX and ETX are ASCII. BCC = XOR of every byte after STX up to and
// including ETX. A response carries no SID; a frame-level error (end code other than
// "00"/"0F") carries no text at all.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "fins/byte_io.hpp"

namespace fins::compoway_f {

inline constexpr std::uint8_t stx = 0x02;
inline constexpr std::uint8_t etx = 0x03;
// Node "XX" is a broadcast: no slave answers it (frames-serial-files.md 1.1).
inline constexpr std::array<std::uint8_t, 2> broadcast_node{'X', 'X'};
// node + sub-address + SID + MRC SRC: the shortest command body.
inline constexpr std::size_t command_header_size = 9;
// node + sub-address + end code: a frame-error response; + MRC SRC + MRES SRES: full.
inline constexpr std::size_t response_error_size = 6;
inline constexpr std::size_t response_header_size = 14;
// A bound for one frame on the line (the E5_C echoback takes 200 data bytes; FINS limits
// the 28 03 text to fewer than 2,000): anything longer is garbage, not a frame.
inline constexpr std::size_t max_frame_size = 2'048;

// The end codes of the frame-level result (frames-serial-files.md 1.3).
namespace end_code {
inline constexpr std::array<std::uint8_t, 2> normal{'0', '0'};
inline constexpr std::array<std::uint8_t, 2> fins_error{'0', 'F'};
inline constexpr std::array<std::uint8_t, 2> parity{'1', '0'};
inline constexpr std::array<std::uint8_t, 2> framing{'1', '1'};
inline constexpr std::array<std::uint8_t, 2> overrun{'1', '2'};
inline constexpr std::array<std::uint8_t, 2> bcc{'1', '3'};
inline constexpr std::array<std::uint8_t, 2> format{'1', '4'};
inline constexpr std::array<std::uint8_t, 2> sub_address{'1', '6'};
inline constexpr std::array<std::uint8_t, 2> frame_length{'1', '8'};
}  // namespace end_code

// XOR of `bytes` (pass node .. ETX).
std::uint8_t bcc(Bytes bytes) noexcept;

// STX + body + ETX + BCC. `body` is everything between STX and ETX.
void write_frame(ByteWriter& w, Bytes body) noexcept;

// One frame found in a byte stream.
struct FrameParse {
    enum class Status : std::uint8_t {
        need_more,     // no ETX + BCC yet (bytes before STX are skipped)
        complete,      // body is valid
        bad_checksum,  // ETX found, BCC wrong
        too_long,      // no ETX within max_frame_size
    };
    Status status = Status::need_more;
    std::size_t consumed = 0;  // bytes of the stream this frame (and leading noise) used
    Bytes body;                // between STX and ETX (views into the stream)
};
// Finds the first STX and its ETX + BCC; a second STX before ETX restarts the frame
// (the slaves' rule, frames-serial-files.md 1.1).
FrameParse parse_frame(Bytes stream) noexcept;

struct Command {
    std::array<std::uint8_t, 2> node{'0', '1'};
    std::array<std::uint8_t, 2> sub_address{'0', '0'};
    std::uint8_t service_id = '0';
    std::array<std::uint8_t, 4> command{};  // MRC SRC, ASCII
    Bytes text;                             // a view
};
// A command body; nothing when shorter than the header.
std::optional<Command> decode_command(Bytes body) noexcept;
void encode_command(ByteWriter& w, const Command& command) noexcept;

struct Response {
    std::array<std::uint8_t, 2> node{};
    std::array<std::uint8_t, 2> sub_address{};
    std::array<std::uint8_t, 2> end_code{};
    bool has_text = false;                  // false: a frame error, nothing after the end code
    std::array<std::uint8_t, 4> command{};  // MRC SRC echo
    std::array<std::uint8_t, 4> response_code{};  // MRES SRES
    Bytes text;                                   // a view
};
// A response body: exactly 6 bytes (frame error) or at least 14; nothing otherwise.
std::optional<Response> decode_response(Bytes body) noexcept;
void encode_response(ByteWriter& w, const Response& response) noexcept;

}  // namespace fins::compoway_f
