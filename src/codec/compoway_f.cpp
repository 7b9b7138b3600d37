// CompoWay/F framing (see fins/compoway_f.hpp; frames-serial-files.md section 1).
#include "fins/compoway_f.hpp"

#include <algorithm>

namespace fins::compoway_f {

namespace {

template <std::size_t N>
std::array<std::uint8_t, N> take(ByteReader& r) noexcept {
    std::array<std::uint8_t, N> out{};
    const Bytes b = r.bytes(N);
    std::copy(b.begin(), b.end(), out.begin());
    return out;
}

}  // namespace

std::uint8_t bcc(Bytes bytes) noexcept {
    std::uint8_t x = 0;
    for (auto b : bytes)
        x ^= b;
    return x;
}

void write_frame(ByteWriter& w, Bytes body) noexcept {
    w.u8(stx);
    w.bytes(body);
    w.u8(etx);
    const std::uint8_t etx_byte[] = {etx};
    w.u8(static_cast<std::uint8_t>(bcc(body) ^ bcc(etx_byte)));
}

FrameParse parse_frame(Bytes stream) noexcept {
    FrameParse result;
    std::size_t start = stream.size();
    for (std::size_t i = 0; i < stream.size(); ++i) {
        if (stream[i] == stx) {
            start = i;  // a new STX restarts the frame
            continue;
        }
        if (start == stream.size()) continue;  // noise before the first STX
        if (i - start > max_frame_size) {
            result.status = FrameParse::Status::too_long;
            result.consumed = i;
            return result;
        }
        if (stream[i] != etx) continue;
        if (i + 1 >= stream.size()) break;                           // BCC still to come
        const Bytes covered = stream.subspan(start + 1, i - start);  // node .. ETX
        result.consumed = i + 2;
        result.body = stream.subspan(start + 1, i - start - 1);
        result.status = bcc(covered) == stream[i + 1] ? FrameParse::Status::complete
                                                      : FrameParse::Status::bad_checksum;
        return result;
    }
    // Nothing complete: keep from the last STX on (noise before it can go).
    result.consumed = start == stream.size() ? stream.size() : start;
    return result;
}

std::optional<Command> decode_command(Bytes body) noexcept {
    if (body.size() < command_header_size) return std::nullopt;
    ByteReader r(body);
    Command c;
    c.node = take<2>(r);
    c.sub_address = take<2>(r);
    c.service_id = r.u8();
    c.command = take<4>(r);
    c.text = r.rest();
    return c;
}

void encode_command(ByteWriter& w, const Command& c) noexcept {
    w.bytes(c.node);
    w.bytes(c.sub_address);
    w.u8(c.service_id);
    w.bytes(c.command);
    w.bytes(c.text);
}

std::optional<Response> decode_response(Bytes body) noexcept {
    if (body.size() != response_error_size && body.size() < response_header_size)
        return std::nullopt;
    ByteReader r(body);
    Response p;
    p.node = take<2>(r);
    p.sub_address = take<2>(r);
    p.end_code = take<2>(r);
    if (r.remaining() == 0) return p;
    p.has_text = true;
    p.command = take<4>(r);
    p.response_code = take<4>(r);
    p.text = r.rest();
    return p;
}

void encode_response(ByteWriter& w, const Response& p) noexcept {
    w.bytes(p.node);
    w.bytes(p.sub_address);
    w.bytes(p.end_code);
    if (!p.has_text) return;
    w.bytes(p.command);
    w.bytes(p.response_code);
    w.bytes(p.text);
}

}  // namespace fins::compoway_f
