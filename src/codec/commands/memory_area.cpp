// I/O memory area access commands 01 01 .. 01 05 (W342 5-3-2 .. 5-3-6, frames 6).
//
// Server side (decode): errors are the end codes the CPU Unit answers, 1002 for a
// command shorter than its fixed part and 1001 for one longer than it.
// Client side (decode_response): any length or echo mismatch is malformed_response.
#include "fins/commands/memory_area.hpp"
#include "codec/command_codec.hpp"

namespace fins {

using codec::check_fixed;
using codec::empty_response;
using codec::end_code;
using codec::malformed;

namespace {

// Fixed parameter sizes (frames 6).
constexpr std::size_t read_size = memory_address_size + 2;          // address, count
constexpr std::size_t write_fixed_size = memory_address_size + 2;   // then the data
constexpr std::size_t fill_size = memory_address_size + 2 + 2;      // address, count, value
constexpr std::size_t transfer_size = 2 * memory_address_size + 2;  // src, dst, count

void write_address(ByteWriter& w, const MemoryAddress& a) noexcept {
    w.u8(a.area_code);
    w.u16(a.word);
    w.u8(a.bit);
}

MemoryAddress read_address(ByteReader& r) noexcept {
    MemoryAddress a;
    a.area_code = r.u8();
    a.word = r.u16();
    a.bit = r.u8();
    return a;
}

}  // namespace

void MemoryAreaReadResponse::encode(ByteWriter& w) const noexcept {
    w.bytes(data);
}

void MemoryAreaRead::encode(ByteWriter& w) const noexcept {
    write_address(w, start);
    w.u16(count);
}

Result<MemoryAreaRead> MemoryAreaRead::decode(Bytes parameters) noexcept {
    if (auto ec = check_fixed(parameters, read_size)) return Unexpected(ec);
    ByteReader r(parameters);
    MemoryAreaRead c;
    c.start = read_address(r);
    c.count = r.u16();
    return c;
}

Result<MemoryAreaRead::Response> MemoryAreaRead::decode_response(Bytes data) const {
    const std::size_t size = element_size(start.area_code);
    // Without the element size the length cannot be checked, so the data cannot be trusted.
    if (size == 0 || data.size() != size * count) return malformed();
    return Response{std::vector<std::uint8_t>(data.begin(), data.end())};
}

void MemoryAreaWrite::encode(ByteWriter& w) const noexcept {
    write_address(w, start);
    w.u16(count);
    w.bytes(data);
}

Result<MemoryAreaWrite> MemoryAreaWrite::decode(Bytes parameters) noexcept {
    if (parameters.size() < write_fixed_size) return end_code(EndCode::command_too_short);
    ByteReader r(parameters);
    MemoryAreaWrite c;
    c.start = read_address(r);
    c.count = r.u16();
    c.data = r.rest();
    return c;
}

Result<MemoryAreaWrite::Response> MemoryAreaWrite::decode_response(Bytes response) const {
    return empty_response(response);
}

void MemoryAreaFill::encode(ByteWriter& w) const noexcept {
    write_address(w, start);
    w.u16(count);
    w.u16(value);
}

Result<MemoryAreaFill> MemoryAreaFill::decode(Bytes parameters) noexcept {
    if (auto ec = check_fixed(parameters, fill_size)) return Unexpected(ec);
    ByteReader r(parameters);
    MemoryAreaFill c;
    c.start = read_address(r);
    c.count = r.u16();
    c.value = r.u16();
    return c;
}

Result<MemoryAreaFill::Response> MemoryAreaFill::decode_response(Bytes data) const {
    return empty_response(data);
}

void MultipleMemoryAreaReadResponse::encode(ByteWriter& w) const noexcept {
    for (const auto& item : items) {
        w.u8(item.area_code);
        switch (element_size(item.area_code)) {
            case 1:
                w.u8(static_cast<std::uint8_t>(item.value));
                break;
            case 2:
                w.u16(static_cast<std::uint16_t>(item.value));
                break;
            case 4:
                w.u32(item.value);
                break;
            default:
                break;  // unknown code: a server never answers one (it fails 1101)
        }
    }
}

void MultipleMemoryAreaRead::encode(ByteWriter& w) const noexcept {
    for (const auto& item : items)
        write_address(w, item);
}

Result<MultipleMemoryAreaRead> MultipleMemoryAreaRead::decode(Bytes parameters) {
    if (parameters.size() > max_multiple_read_elements * memory_address_size)
        return end_code(EndCode::command_too_long);
    if (parameters.size() % memory_address_size != 0) return end_code(EndCode::command_too_short);
    ByteReader r(parameters);
    MultipleMemoryAreaRead c;
    c.items.reserve(parameters.size() / memory_address_size);
    while (r.remaining() != 0)
        c.items.push_back(read_address(r));
    return c;
}

Result<MultipleMemoryAreaRead::Response> MultipleMemoryAreaRead::decode_response(Bytes data) const {
    ByteReader r(data);
    Response response;
    response.items.reserve(items.size());
    for (const auto& item : items) {
        Response::Item got;
        got.area_code = r.u8();
        // W342 5-3-5: items come back in request order, each led by its area code.
        if (r.truncated() || got.area_code != item.area_code) return malformed();
        switch (element_size(got.area_code)) {
            case 1:
                got.value = r.u8();
                break;
            case 2:
                got.value = r.u16();
                break;
            case 4:
                got.value = r.u32();
                break;
            default:
                return malformed();
        }
        response.items.push_back(got);
    }
    if (!r.complete()) return malformed();
    return response;
}

void MemoryAreaTransfer::encode(ByteWriter& w) const noexcept {
    write_address(w, source);
    write_address(w, destination);
    w.u16(count);
}

Result<MemoryAreaTransfer> MemoryAreaTransfer::decode(Bytes parameters) noexcept {
    if (auto ec = check_fixed(parameters, transfer_size)) return Unexpected(ec);
    ByteReader r(parameters);
    MemoryAreaTransfer c;
    c.source = read_address(r);
    c.destination = read_address(r);
    c.count = r.u16();
    return c;
}

Result<MemoryAreaTransfer::Response> MemoryAreaTransfer::decode_response(Bytes data) const {
    return empty_response(data);
}

}  // namespace fins
