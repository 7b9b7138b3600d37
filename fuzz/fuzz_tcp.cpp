// Fuzzes the FINS/TCP envelope parser the way a session drives it: parse, consume,
// repeat, until it needs more bytes or reports an error; packet data is handed to the
// handshake and frame decoders.
#include <cstddef>
#include <cstdint>

#include "fins/frame.hpp"
#include "fins/tcp.hpp"

namespace {
void check(bool ok) {
    if (!ok) __builtin_trap();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace fins;
    Bytes buffer(data, size);
    while (!buffer.empty()) {
        const auto p = parse_tcp_frame(buffer);
        check(p.consumed <= buffer.size());
        if (p.status != TcpParse::Status::packet) break;
        check(p.consumed >= tcp_header_size && p.consumed <= tcp_max_packet);
        check(p.packet.data.size() == p.consumed - tcp_header_size);
        switch (static_cast<TcpCommand>(p.packet.command)) {
            case TcpCommand::node_address_request:
                (void)decode_node_address_request(p.packet.data);
                break;
            case TcpCommand::node_address_response:
                (void)decode_node_address_response(p.packet.data);
                break;
            case TcpCommand::frame:
                (void)decode_request(p.packet.data);
                (void)decode_response(p.packet.data);
                break;
            default:
                break;
        }
        buffer = buffer.subspan(p.consumed);
    }
    return 0;
}
