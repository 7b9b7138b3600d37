// FINS over Host Link (W342 3-5 "FINS Commands with Host Link Protocol", 5-3-1 "Using
// Host Link Communications"; frames: fins-frames.md section 4, frames-serial-files.md
// section 3). Pure codec: ASCII Host Link frames <-> binary FINS frames, no I/O.
//
// Every character is ASCII; every FINS byte is two uppercase hex characters.
//   command, direct form (to the directly connected CPU Unit, ICF "00"):
//     "@" UU "FA" W  ICF DA2 SA2 SID  MRC SRC  text  FCS "*" CR
//   command, network form (ICF "80", the whole 10-byte FINS header):
//     "@" UU "FA" W  ICF RSV GCT DNA DA1 DA2 SNA SA1 SA2 SID  MRC SRC  text  FCS "*" CR
//   response (direct: ICF "40" DA2 SA2 SID; network: ICF "C0" and the whole header):
//     "@" UU "FA" EC  [header]  MRC SRC  MRES SRES  data  FCS "*" CR
//   error response (EC not "00"; our choice, see docs/serial.md "Host Link end codes"):
//     "@" UU "FA" EC  FCS "*" CR
// UU: Host Link unit number, two decimal digits 00-31. W: response wait time, one hex
// digit, in 10 ms. EC: Host Link end code. FCS: XOR of every character from "@" through
// the last text character, two hex characters. The CPU-initiated form uses header code
// "OF" instead of "FA" with the network layout (wait "0", ICF 80/81); its answer is the
// network response form with "OF".
//
// Binary side: decode writes a whole binary FINS frame (10-byte header), so the client's
// request tracker and the server's dispatcher work unchanged. For the direct form the
// fields the frame does not carry are filled in: RSV 00, GCT 02, DNA/DA1/SNA/SA1 00
// (the local network and PLC); encoding the direct form drops them again.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <system_error>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

// W342 p. 69/79 (frames-serial-files.md section 3): command <= 1,114 characters,
// response <= 1,115 characters, response data <= 1,076 characters (538 bytes).
inline constexpr std::size_t host_link_max_command_chars = 1114;
inline constexpr std::size_t host_link_max_response_chars = 1115;
// Text after MRC SRC: <= 1,080 characters (540 bytes) in a command.
inline constexpr std::size_t host_link_max_parameter_bytes = 540;
inline constexpr std::size_t host_link_max_response_data_bytes = 538;
// Binary FINS frames that fit in a Host Link frame.
inline constexpr std::size_t host_link_max_fins_command =
    header_size + command_code_size + host_link_max_parameter_bytes;
inline constexpr std::size_t host_link_max_fins_response =
    header_size + command_code_size + end_code_size + host_link_max_response_data_bytes;
// W342 5-2-2 "Number of Elements": the SYSWAY (Host Link) limits, 269 read, 267 written.
inline constexpr std::uint16_t host_link_max_read_words = 269;
inline constexpr std::uint16_t host_link_max_write_words = 267;
// Host Link unit numbers 00-31 (W342 3-5).
inline constexpr std::uint8_t host_link_max_unit = 31;
inline constexpr std::uint8_t host_link_terminator[2] = {'*', '\r'};

// Host Link end codes (W342 4-2, C-mode codes of the CS/CJ CPU Units). Which of them an
// "FA" frame can get is not in the sources; finsd answers 13, 14, 16 and 18 (docs/serial.md).
enum class HostLinkEndCode : std::uint8_t {
    normal = 0x00,
    not_executable_in_run = 0x01,
    not_executable_in_monitor = 0x02,
    um_write_protected = 0x03,
    address_over = 0x04,
    not_executable_in_program = 0x0B,
    fcs_error = 0x13,
    format_error = 0x14,
    entry_number_error = 0x15,
    command_not_supported = 0x16,
    frame_length_error = 0x18,
    not_executable = 0x19,
    io_table_not_created = 0x20,
    cpu_unit_error = 0x21,
    user_memory_protected = 0x23,
    aborted_fcs_error = 0xA3,
    aborted_format_error = 0xA4,
    aborted_entry_number_error = 0xA5,
    aborted_frame_length_error = 0xA8,
};
// "FCS error (Host Link end code 13)".
const std::error_category& host_link_end_code_category() noexcept;
std::error_code make_error_code(HostLinkEndCode e) noexcept;

// Failures seen locally in what a Host Link peer sent (decode errors of an answer).
enum class HostLinkError : int {
    bad_fcs = 1,  // the frame's FCS does not match its characters
    format,       // not a Host Link FINS frame: bad characters, lengths or header
    too_long,     // over the length limits above
    wrong_unit,   // an answer from another unit number than the one asked
};
const std::error_category& host_link_category() noexcept;
std::error_code make_error_code(HostLinkError e) noexcept;

enum class HostLinkHeaderCode : std::uint8_t { fa, of };  // "FA" host->CPU, "OF" CPU->host
enum class HostLinkForm : std::uint8_t { direct, network };

// What a decoded frame was; the FINS frame itself went to the caller's buffer.
struct HostLinkFrame {
    std::uint8_t unit = 0;
    HostLinkHeaderCode header_code = HostLinkHeaderCode::fa;
    HostLinkForm form = HostLinkForm::direct;
    bool response = false;
    std::uint8_t wait = 0;  // command: response wait time digit, in 10 ms
    HostLinkEndCode end_code = HostLinkEndCode::normal;  // response only
    std::size_t fins_size = 0;                           // bytes written; 0 for an error response
};

// FCS of `text` (every character from "@" through the last text character).
std::uint8_t host_link_fcs(Bytes text) noexcept;

// Encodes a binary FINS command frame (from encode_request) as a Host Link command.
// Direct form keeps ICF 00, DA2, SA2, SID and the command; network form keeps all.
// Fails with HostLinkError::too_long (parameters over 540 bytes or `out` too small),
// HostLinkError::format (frame shorter than header + command code, unit over 31, wait
// over F).
Result<std::size_t> encode_host_link_command(
    std::uint8_t unit, std::uint8_t wait, HostLinkForm form, Bytes fins_command, MutableBytes out,
    HostLinkHeaderCode code = HostLinkHeaderCode::fa) noexcept;
// Encodes a binary FINS response frame (from the dispatcher) with end code "00".
Result<std::size_t> encode_host_link_response(
    std::uint8_t unit, HostLinkForm form, Bytes fins_response, MutableBytes out,
    HostLinkHeaderCode code = HostLinkHeaderCode::fa) noexcept;
// "@" UU "FA" EC FCS "*" CR: 11 characters. `out` must hold them.
std::size_t encode_host_link_error(std::uint8_t unit, HostLinkEndCode end_code, MutableBytes out,
                                   HostLinkHeaderCode code = HostLinkHeaderCode::fa) noexcept;
inline constexpr std::size_t host_link_error_size = 11;

// Decodes one whole frame ("@" through CR). `response` says which kind the caller
// expects (a slave decodes commands, a host responses). The FINS frame goes to
// `fins_out` (host_link_max_fins_response bytes are always enough).
// Errors, checked in this order (what a slave answers, docs/serial.md): frame too short, no
// "*" CR, unit not 2 decimal digits -> format (a slave ignores those: it cannot tell the
// unit); FCS mismatch -> bad_fcs; frame over the length limit -> too_long; a header
// code other than FA/OF -> format with `not_fins` set (C-mode "16"); odd or non-hex
// text, a header too short -> format.
struct HostLinkDecodeError {
    HostLinkError error = HostLinkError::format;
    std::int16_t unit = -1;  // the unit number when it could be read, else -1
    bool not_fins = false;   // a well-formed Host Link frame with another header code
};
tl::expected<HostLinkFrame, HostLinkDecodeError> decode_host_link(Bytes frame, bool response,
                                                                  MutableBytes fins_out) noexcept;
// The end code a slave answers for a decode error: 13, 16, 18 or 14.
HostLinkEndCode host_link_answer_for(const HostLinkDecodeError& e) noexcept;

// Incremental frame finder over a byte stream. Looks at the start of `buffer`:
// - garbage: bytes before the next "@" (consumed says how many) - skip them;
// - frame: "@" through the first CR (consumed = its length);
// - need_more: "@" and no CR yet, within the limit;
// - too_long: "@" and no CR within `limit` characters; consumed = limit (the rest of
//   that frame is garbage for the next call). Over-long frames get no answer (C-mode
//   rule, W342 4-2: over-long frames set the Reception Overflow Flag, no response).
struct HostLinkScan {
    enum class Status { need_more, frame, garbage, too_long };
    Status status = Status::need_more;
    std::size_t consumed = 0;
    Bytes frame;  // status == frame: a view into buffer
};
HostLinkScan scan_host_link(Bytes buffer,
                            std::size_t limit = host_link_max_response_chars) noexcept;

}  // namespace fins

template <>
struct std::is_error_code_enum<fins::HostLinkEndCode> : std::true_type {};
template <>
struct std::is_error_code_enum<fins::HostLinkError> : std::true_type {};
