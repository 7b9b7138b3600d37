// FINS frame header and whole-frame codecs (W342 3-1, frames 1.1-1.6).
#include "fins/frame.hpp"

namespace fins {

void write_header(ByteWriter& w, const Header& h) noexcept {
    w.u8(h.icf);
    w.u8(h.reserved);
    w.u8(h.gateway_count);
    w.u8(h.destination.network);
    w.u8(h.destination.node);
    w.u8(h.destination.unit);
    w.u8(h.source.network);
    w.u8(h.source.node);
    w.u8(h.source.unit);
    w.u8(h.service_id);
}

Header read_header(ByteReader& r) noexcept {
    Header h;
    h.icf = r.u8();
    h.reserved = r.u8();
    h.gateway_count = r.u8();
    h.destination.network = r.u8();
    h.destination.node = r.u8();
    h.destination.unit = r.u8();
    h.source.network = r.u8();
    h.source.node = r.u8();
    h.source.unit = r.u8();
    h.service_id = r.u8();
    return h;
}

Result<RequestView> decode_request(Bytes frame) noexcept {
    if (frame.size() < header_size + command_code_size)
        return Unexpected(make_error_code(EndCode::command_too_short));
    if (frame.size() > max_frame_size)
        return Unexpected(make_error_code(EndCode::command_too_long));
    ByteReader r(frame);
    RequestView v;
    v.header = read_header(r);
    // A response arriving where a command is expected must never be answered (a reply to
    // a reply could loop between two nodes); the dispatcher drops header errors silently.
    if (v.header.is_response()) return Unexpected(make_error_code(EndCode::header_error));
    v.command.main = r.u8();
    v.command.sub = r.u8();
    v.parameters = r.rest();
    return v;
}

Result<ResponseView> decode_response(Bytes frame) noexcept {
    const auto malformed = Unexpected(make_error_code(ClientError::malformed_response));
    if (frame.size() < header_size + command_code_size + end_code_size) return malformed;
    ByteReader r(frame);
    ResponseView v;
    v.header = read_header(r);
    if (!v.header.is_response()) return malformed;
    v.command.main = r.u8();
    v.command.sub = r.u8();
    v.code = ResponseCode(r.u16());
    if (v.code.relay_error()) {
        // W342 5-1-3: bit 15 adds one word naming the network and node that failed.
        RelayErrorSource relay;
        relay.network = r.u8();
        relay.node = r.u8();
        if (r.truncated()) return malformed;
        v.relay = relay;
    }
    v.data = r.rest();
    return v;
}

Result<std::size_t> encode_request(const Header& h, CommandCode c, Bytes parameters,
                                   MutableBytes out) noexcept {
    const std::size_t total = header_size + command_code_size + parameters.size();
    if (parameters.size() > max_parameter_size || total > out.size())
        return Unexpected(make_error_code(ClientError::request_too_long));
    ByteWriter w(out);
    write_header(w, h);
    w.u8(c.main);
    w.u8(c.sub);
    w.bytes(parameters);
    return w.size();
}

Header response_header(const Header& request, const NodeAddress& responder) noexcept {
    Header h;
    h.icf = static_cast<std::uint8_t>(request.icf | icf_response);
    h.reserved = 0;
    h.gateway_count = request.gateway_count;
    h.destination = request.source;
    h.source = request.destination;
    // A request may name the responder as "local network" (DNA 00) or "local PLC"
    // (DA1 00); the requester still needs to see who answered (frames 1.5 leaves this
    // open), so the responder reports its real address instead of echoing 00.
    if (h.source.network == local_network) h.source.network = responder.network;
    if (h.source.node == 0) h.source.node = responder.node;
    h.service_id = request.service_id;
    return h;
}

void write_response_prefix(ByteWriter& w, const Header& response_header, CommandCode c,
                           std::uint16_t end_code) noexcept {
    write_header(w, response_header);
    w.u8(c.main);
    w.u8(c.sub);
    w.u16(end_code);
}

}  // namespace fins
