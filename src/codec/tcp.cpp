// The FINS/TCP envelope (W421 7-4, frames section 3).
#include "fins/tcp.hpp"

#include <algorithm>

namespace fins {
namespace {

constexpr std::size_t magic_size = 4;
constexpr std::size_t length_field_end = 8;    // magic + length
constexpr std::size_t command_and_error = 8;   // what the length field counts before data
constexpr std::size_t node_request_data = 4;   // client node (frames 3.2)
constexpr std::size_t node_response_data = 8;  // client node, server node

constexpr std::uint8_t magic_bytes[magic_size] = {'F', 'I', 'N', 'S'};

}  // namespace

TcpParse parse_tcp_frame(Bytes buffer) noexcept {
    TcpParse p;
    // Check the magic as soon as its first bytes arrive: a peer that is not speaking
    // FINS/TCP is told so without waiting for a length that may never come.
    const std::size_t seen = std::min(buffer.size(), magic_size);
    if (!std::equal(buffer.begin(), buffer.begin() + static_cast<std::ptrdiff_t>(seen),
                    magic_bytes)) {
        p.status = TcpParse::Status::error;
        p.error = TcpError::not_fins_header;
        p.consumed = seen;
        return p;
    }
    if (buffer.size() < length_field_end) return p;

    ByteReader r(buffer);
    r.skip(magic_size);
    const std::uint32_t length = r.u32();
    if (length < command_and_error || length > tcp_max_length) {
        p.status = TcpParse::Status::error;
        p.error = TcpError::data_length_too_long;
        p.consumed = length_field_end;
        return p;
    }
    const std::size_t total = length_field_end + length;
    if (buffer.size() < total) return p;

    p.status = TcpParse::Status::packet;
    p.consumed = total;
    p.packet.command = r.u32();
    p.packet.error = r.u32();
    p.packet.data = r.bytes(length - command_and_error);
    return p;
}

void write_tcp_header(ByteWriter& w, TcpCommand command, std::size_t data_size,
                      std::uint32_t error) noexcept {
    w.u32(tcp_magic);
    // Sizes come from the caller's own frames (at most 2,012 bytes), so the cast is safe;
    // an oversized value is clamped to one the peer will reject rather than wrapped.
    const std::size_t length = std::min<std::size_t>(command_and_error + data_size, 0xFFFFFFFF);
    w.u32(static_cast<std::uint32_t>(length));
    w.u32(static_cast<std::uint32_t>(command));
    w.u32(error);
}

void write_node_address_request(ByteWriter& w, std::uint8_t client_node) noexcept {
    write_tcp_header(w, TcpCommand::node_address_request, node_request_data);
    w.u32(client_node);
}

void write_node_address_response(ByteWriter& w, std::uint32_t client_node, std::uint8_t server_node,
                                 std::uint32_t error) noexcept {
    write_tcp_header(w, TcpCommand::node_address_response, node_response_data, error);
    w.u32(client_node);
    w.u32(server_node);
}

void write_tcp_error(ByteWriter& w, TcpCommand command, TcpError error) noexcept {
    write_tcp_header(w, command, 0, static_cast<std::uint32_t>(error));
}

Result<std::uint8_t> decode_node_address_request(Bytes data) noexcept {
    // The envelope gave a length that does not fit command 0; FINS/TCP has no closer code.
    if (data.size() != node_request_data)
        return Unexpected(make_error_code(TcpError::data_length_too_long));
    // W421 7-4 command 0: 00000000-000000FE. A value above FE (e.g. 00000105) is out of
    // range as a whole, not its low byte.
    ByteReader r(data);
    const std::uint32_t node = r.u32();
    if (node > max_client_node)
        return Unexpected(make_error_code(TcpError::client_node_out_of_range));
    return static_cast<std::uint8_t>(node);
}

Result<NodeAddressResponse> decode_node_address_response(Bytes data) noexcept {
    if (data.size() != node_response_data)
        return Unexpected(make_error_code(ClientError::malformed_response));
    return NodeAddressResponse{data[3], data[7]};
}

}  // namespace fins
