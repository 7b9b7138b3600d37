// The FINS frame: 10-byte header, 2-byte command code, parameters (W342 3-1, frames 1.1).
//
// Requests:  ICF RSV GCT DNA DA1 DA2 SNA SA1 SA2 SID MRC SRC <parameters 0..2000>
// Responses: the same header with ICF bit 6 set, MRC SRC, MRES SRES end code,
//            [relay-error network, node when end-code bit 15 is on], data.
// Decoding returns views into the caller's buffer; nothing here allocates.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"

namespace fins {

// Frame limits (W421 7-2; W596 1-2 "Max. 2,012 bytes").
inline constexpr std::size_t header_size = 10;
inline constexpr std::size_t command_code_size = 2;
inline constexpr std::size_t end_code_size = 2;
inline constexpr std::size_t max_frame_size = 2012;
inline constexpr std::size_t max_parameter_size = max_frame_size - header_size - command_code_size;
inline constexpr std::size_t max_response_data_size =
    max_frame_size - header_size - command_code_size - end_code_size;

// ICF bits (frames 1.2).
inline constexpr std::uint8_t icf_gateway = 0x80;
inline constexpr std::uint8_t icf_response = 0x40;
inline constexpr std::uint8_t icf_no_response = 0x01;

// Default gateway count: 02 is what every unit accepts; CS/CJ ver. 2.0+ accept 07 (frames 1.3).
inline constexpr std::uint8_t default_gateway_count = 0x02;

// Special node and unit numbers (frames 1.3, 1.4).
inline constexpr std::uint8_t local_network = 0x00;
inline constexpr std::uint8_t broadcast_node = 0xFF;
inline constexpr std::uint8_t cpu_unit = 0x00;
inline constexpr std::uint8_t inner_board_unit = 0xE1;  // e.g. a Loop Control Board
inline constexpr std::uint8_t network_unit = 0xFE;

struct NodeAddress {
    std::uint8_t network = 0;  // DNA/SNA: 00 local network, 01-7F
    std::uint8_t node = 0;     // DA1/SA1: 00 local PLC, 01-FE, FF broadcast
    std::uint8_t unit = 0;     // DA2/SA2: 00 CPU Unit, 10-1F CPU Bus Unit, FE network unit ...
    friend constexpr bool operator==(const NodeAddress&, const NodeAddress&) = default;
};

struct CommandCode {
    std::uint8_t main = 0;  // MRC
    std::uint8_t sub = 0;   // SRC
    [[nodiscard]] constexpr std::uint16_t value() const noexcept {
        return static_cast<std::uint16_t>((main << 8) | sub);
    }
    friend constexpr bool operator==(const CommandCode&, const CommandCode&) = default;
};

struct Header {
    std::uint8_t icf = icf_gateway;
    std::uint8_t reserved = 0;
    std::uint8_t gateway_count = default_gateway_count;
    NodeAddress destination;
    NodeAddress source;
    std::uint8_t service_id = 0;  // SID: echoed by the responder

    [[nodiscard]] constexpr bool is_response() const noexcept { return (icf & icf_response) != 0; }
    [[nodiscard]] constexpr bool response_required() const noexcept {
        return (icf & icf_no_response) == 0;
    }
    friend constexpr bool operator==(const Header&, const Header&) = default;
};

struct RequestView {
    Header header;
    CommandCode command;
    Bytes parameters;
};

struct ResponseView {
    Header header;
    CommandCode command;
    ResponseCode code;
    std::optional<RelayErrorSource> relay;  // present when code.relay_error()
    Bytes data;
};

void write_header(ByteWriter& w, const Header& h) noexcept;
Header read_header(ByteReader& r) noexcept;

// Whole-frame codecs. decode_request (server side) fails, with FINS end codes, only for
// frames too short to carry a header and command code (EndCode::command_too_short),
// longer than 2,012 bytes (EndCode::command_too_long), or whose ICF marks a response
// (EndCode::header_error).
Result<RequestView> decode_request(Bytes frame) noexcept;
// Fails with ClientError::malformed_response when shorter than header + command + end code,
// when ICF lacks the response bit, or when bit 15 is set without the relay word.
Result<ResponseView> decode_response(Bytes frame) noexcept;

// Writes header + command code + parameters; returns bytes written or
// ClientError::request_too_long when it does not fit in out or exceeds 2,012 bytes.
Result<std::size_t> encode_request(const Header& h, CommandCode c, Bytes parameters,
                                   MutableBytes out) noexcept;

// The header a responder sends back: ICF with the response bit, GCT echoed, source and
// destination swapped, SID echoed. `responder` is the responder's real address, used
// when the request addressed it as "local" (node 00).
Header response_header(const Header& request, const NodeAddress& responder) noexcept;

// Writes the response frame prefix (header, command, end code), leaving the writer
// positioned at the start of the response data.
void write_response_prefix(ByteWriter& w, const Header& response_header, CommandCode c,
                           std::uint16_t end_code) noexcept;

}  // namespace fins
