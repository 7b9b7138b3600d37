// 02 40 READ MULTIPLE ITEMS FROM FUNCTION BLOCK (seed 001, frames 8).
//
// Server side (decode): errors are the Loop Control Board's own response codes for the
// command's shape (1001, 1002, 1003); block and ITEM checks belong to the handler.
// Client side (decode_response): any length or order mismatch is malformed_response.
#include "codec/command_codec.hpp"
#include "fins/commands/loop_control.hpp"

#include <utility>

namespace fins {

using codec::end_code;
using codec::malformed;

namespace {

constexpr std::size_t fixed_size = 4;  // block address, number of ITEMs
constexpr std::size_t max_parameters = max_loop_command_bytes - command_code_size;
constexpr std::size_t min_parameters = min_loop_command_bytes - command_code_size;

}  // namespace

void FunctionBlockItemReadResponse::encode(ByteWriter& w) const noexcept {
    w.u16(static_cast<std::uint16_t>(items.size()));
    for (const auto& item : items) {
        w.u16(item.item);
        w.u8(static_cast<std::uint8_t>(item.data.size()));
        w.bytes(item.data);
    }
}

void FunctionBlockItemRead::encode(ByteWriter& w) const noexcept {
    w.u16(block);
    w.u16(static_cast<std::uint16_t>(items.size()));
    for (auto item : items)
        w.u16(item);
}

Result<FunctionBlockItemRead> FunctionBlockItemRead::decode(Bytes parameters) {
    static_assert(min_parameters == fixed_size);
    if (parameters.size() > max_parameters) return end_code(EndCode::command_too_long);
    if (parameters.size() < min_parameters) return end_code(EndCode::command_too_short);
    ByteReader r(parameters);
    FunctionBlockItemRead c;
    c.block = r.u16();
    const std::size_t declared = r.u16();
    // Seed 001 1003: "the number of read start addresses does not match the number of
    // ITEMs"; a half address at the end is a mismatch too.
    if (r.remaining() != declared * 2) return end_code(EndCode::elements_data_mismatch);
    c.items.reserve(declared);
    for (std::size_t i = 0; i < declared; ++i)
        c.items.push_back(r.u16());
    return c;
}

Result<FunctionBlockItemRead::Response> FunctionBlockItemRead::decode_response(Bytes data) const {
    ByteReader r(data);
    const std::size_t count = r.u16();
    if (r.truncated() || count > items.size()) return malformed();
    Response response;
    response.items.reserve(count);
    std::size_t next = 0;  // ITEMs come back in request order, some possibly left out
    for (std::size_t i = 0; i < count; ++i) {
        Response::Item item;
        item.item = r.u16();
        const std::size_t length = r.u8();
        const auto bytes = r.bytes(length);
        if (r.truncated()) return malformed();
        while (next < items.size() && items[next] != item.item)
            ++next;
        if (next == items.size()) return malformed();
        ++next;
        item.data.assign(bytes.begin(), bytes.end());
        response.items.push_back(std::move(item));
    }
    if (!r.complete()) return malformed();
    return response;
}

}  // namespace fins
