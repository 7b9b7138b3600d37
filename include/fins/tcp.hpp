// The FINS/TCP envelope (W421 7-4, frames section 3): a 16-byte header of four
// big-endian 32-bit fields, "FINS" magic, length (bytes after the length field),
// command, error code, then the command's data. Pure codec: the transport owns the
// buffer and feeds whatever bytes it has; parse_tcp_frame() says "need more", gives a
// complete frame as a view, or reports the envelope error the peer must be told.
#pragma once

#include <cstddef>
#include <cstdint>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"
#include "fins/frame.hpp"

namespace fins {

inline constexpr std::uint32_t tcp_magic = 0x46494E53;  // "FINS"
inline constexpr std::size_t tcp_header_size = 16;
// Length field = 8 (command + error) + data; a FRAME SEND carries at most 2,012 bytes.
inline constexpr std::uint32_t tcp_max_length = 8 + max_frame_size;
inline constexpr std::size_t tcp_max_packet = 8 + tcp_max_length;

enum class TcpCommand : std::uint32_t {
    node_address_request = 0,     // client -> server: client node (0 = allocate one)
    node_address_response = 1,    // server -> client: client node, server node
    frame = 2,                    // FRAME SEND: one FINS frame
    frame_error = 3,              // FRAME SEND ERROR NOTIFICATION
    connection_confirmation = 6,  // server -> existing client
};

struct TcpPacket {
    std::uint32_t command = 0;
    std::uint32_t error = 0;
    Bytes data;  // view into the parsed buffer
};

struct TcpParse {
    enum class Status { need_more, packet, error };
    Status status = Status::need_more;
    std::size_t consumed = 0;  // bytes of the buffer the packet (or error) used
    TcpPacket packet;          // valid when status == packet
    TcpError error{};          // valid when status == error: what to send in command 3
};

// Looks at the start of `buffer`. Errors: bad magic -> not_fins_header; length field
// below 8 or above tcp_max_length -> data_length_too_long. Unknown command numbers are
// returned as packets; the caller answers command_not_supported.
TcpParse parse_tcp_frame(Bytes buffer) noexcept;

// Writes a 16-byte header announcing `data_size` bytes of data after it.
void write_tcp_header(ByteWriter& w, TcpCommand command, std::size_t data_size,
                      std::uint32_t error = 0) noexcept;

// Whole packets for the handshake and errors (sizes 20, 24 and 16 bytes).
void write_node_address_request(ByteWriter& w, std::uint8_t client_node) noexcept;
// `client_node` is echoed whole in a refusal (e.g. 00000105 answered with 0x23).
void write_node_address_response(ByteWriter& w, std::uint32_t client_node, std::uint8_t server_node,
                                 std::uint32_t error = 0) noexcept;
void write_tcp_error(ByteWriter& w, TcpCommand command, TcpError error) noexcept;

struct NodeAddressResponse {
    std::uint8_t client_node = 0;
    std::uint8_t server_node = 0;
};
// W421 7-4 command 0: a client node is 00000000-000000FE (0 = allocate one).
inline constexpr std::uint32_t max_client_node = 0xFE;
// Data of a node_address_request (4 bytes) -> client node. A length other than 4 is
// data_length_too_long; a value above FE (255, or 00000105: not its low byte) is
// client_node_out_of_range.
Result<std::uint8_t> decode_node_address_request(Bytes data) noexcept;
// Data of a node_address_response (8 bytes).
Result<NodeAddressResponse> decode_node_address_response(Bytes data) noexcept;

}  // namespace fins
