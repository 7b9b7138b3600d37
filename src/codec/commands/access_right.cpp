// 0C 01 .. 0C 03 access right commands (W342 5-3-24 .. 5-3-26, frames 6/0C01).
// Each command is the 2-byte program number alone; its value is the handler's to check.
#include "codec/command_codec.hpp"
#include "fins/commands/access_right.hpp"

namespace fins {

using codec::malformed;

namespace {

// The program number, or 1002 / 1001 for a block that is not exactly 2 bytes.
Result<std::uint16_t> read_program_number(Bytes parameters) noexcept {
    if (parameters.size() < 2) return Unexpected(make_error_code(EndCode::command_too_short));
    if (parameters.size() > 2) return Unexpected(make_error_code(EndCode::command_too_long));
    ByteReader r(parameters);
    return r.u16();
}

Result<EmptyResponse> expect_empty(Bytes data) {
    if (!data.empty()) return malformed();
    return EmptyResponse{};
}

}  // namespace

void AccessRightHolder::encode(ByteWriter& w) const noexcept {
    w.u8(holder.unit);
    w.u8(holder.node);
    w.u8(holder.network);
}

Result<AccessRightHolder> AccessRightHolder::decode(Bytes data) {
    if (data.size() != size) return malformed();
    ByteReader r(data);
    AccessRightHolder h;
    h.holder.unit = r.u8();
    h.holder.node = r.u8();
    h.holder.network = r.u8();
    return h;
}

void AccessRightAcquire::encode(ByteWriter& w) const noexcept {
    w.u16(program_number);
}

Result<AccessRightAcquire> AccessRightAcquire::decode(Bytes parameters) noexcept {
    auto p = read_program_number(parameters);
    if (!p) return Unexpected(p.error());
    return AccessRightAcquire{*p};
}

Result<AccessRightAcquire::Response> AccessRightAcquire::decode_response(Bytes data) const {
    return expect_empty(data);
}

void AccessRightForcedAcquire::encode(ByteWriter& w) const noexcept {
    w.u16(program_number);
}

Result<AccessRightForcedAcquire> AccessRightForcedAcquire::decode(Bytes parameters) noexcept {
    auto p = read_program_number(parameters);
    if (!p) return Unexpected(p.error());
    return AccessRightForcedAcquire{*p};
}

Result<AccessRightForcedAcquire::Response> AccessRightForcedAcquire::decode_response(
    Bytes data) const {
    return expect_empty(data);
}

void AccessRightRelease::encode(ByteWriter& w) const noexcept {
    w.u16(program_number);
}

Result<AccessRightRelease> AccessRightRelease::decode(Bytes parameters) noexcept {
    auto p = read_program_number(parameters);
    if (!p) return Unexpected(p.error());
    return AccessRightRelease{*p};
}

Result<AccessRightRelease::Response> AccessRightRelease::decode_response(Bytes data) const {
    return expect_empty(data);
}

}  // namespace fins
