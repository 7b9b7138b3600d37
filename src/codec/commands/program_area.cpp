// Program area commands 03 06 .. 03 08 (W342 5-3-10 .. 5-3-12, frames 6).
//
// Server side (decode): errors are the end codes the CPU Unit answers, 1002 for a
// command shorter than its fixed part and 1001 for one longer than it.
// Client side (decode_response): any length or echo mismatch is malformed_response.
#include "codec/command_codec.hpp"
#include "fins/commands/program_area.hpp"

namespace fins {

using codec::check_fixed;
using codec::end_code;
using codec::malformed;

namespace {

// Parameter sizes (frames 6): program number (2), beginning address (4), bytes (2).
constexpr std::size_t read_size = 8;
constexpr std::size_t write_fixed_size = 8;
constexpr std::size_t clear_size = 3;  // program number (2), clear code (1)
constexpr std::size_t echo_size = 8;   // response: program number, address, bytes

std::uint16_t with_flag(std::uint16_t count, bool last) noexcept {
    return static_cast<std::uint16_t>((count & program_count_mask) | (last ? program_last_bit : 0));
}

// The fixed part shared by commands and responses.
struct Block {
    std::uint16_t program_number = 0;
    std::uint32_t address = 0;
    std::uint16_t count = 0;
    bool last = false;
};

Block read_block(ByteReader& r) noexcept {
    Block b;
    b.program_number = r.u16();
    b.address = r.u32();
    const auto raw_count = r.u16();
    b.count = raw_count & program_count_mask;
    b.last = (raw_count & program_last_bit) != 0;
    return b;
}

void write_block(ByteWriter& w, std::uint16_t program_number, std::uint32_t address,
                 std::uint16_t count, bool last) noexcept {
    w.u16(program_number);
    w.u32(address);
    w.u16(with_flag(count, last));
}

}  // namespace

void ProgramAreaReadResponse::encode(ByteWriter& w) const noexcept {
    write_block(w, program_number, address, count, last);
    w.bytes(data);
}

void ProgramAreaRead::encode(ByteWriter& w) const noexcept {
    write_block(w, program_number, address, count, last);
}

Result<ProgramAreaRead> ProgramAreaRead::decode(Bytes parameters) noexcept {
    if (auto ec = check_fixed(parameters, read_size)) return Unexpected(ec);
    ByteReader r(parameters);
    const auto b = read_block(r);
    return ProgramAreaRead{b.program_number, b.address, b.count, b.last};
}

Result<ProgramAreaRead::Response> ProgramAreaRead::decode_response(Bytes data) const {
    if (data.size() < echo_size) return malformed();
    ByteReader r(data);
    const auto b = read_block(r);
    // Fewer bytes than asked only at the end of the area (then bit 15 is on).
    if (b.program_number != program_number || b.address != address || b.count > count)
        return malformed();
    if (r.remaining() != b.count) return malformed();
    const auto bytes = r.rest();
    return Response{b.program_number, b.address, b.count, b.last,
                    std::vector<std::uint8_t>(bytes.begin(), bytes.end())};
}

void ProgramAreaWriteResponse::encode(ByteWriter& w) const noexcept {
    write_block(w, program_number, address, count, last);
}

void ProgramAreaWrite::encode(ByteWriter& w) const noexcept {
    write_block(w, program_number, address, count, last);
    w.bytes(data);
}

Result<ProgramAreaWrite> ProgramAreaWrite::decode(Bytes parameters) noexcept {
    if (parameters.size() < write_fixed_size) return end_code(EndCode::command_too_short);
    ByteReader r(parameters);
    const auto b = read_block(r);
    return ProgramAreaWrite{b.program_number, b.address, b.count, b.last, r.rest()};
}

Result<ProgramAreaWrite::Response> ProgramAreaWrite::decode_response(Bytes response) const {
    if (response.size() != echo_size) return malformed();
    ByteReader r(response);
    const auto b = read_block(r);
    // 5-3-11: program number, address and byte count come back as sent.
    if (b.program_number != program_number || b.address != address || b.count != count)
        return malformed();
    return Response{b.program_number, b.address, b.count, b.last};
}

void ProgramAreaClear::encode(ByteWriter& w) const noexcept {
    w.u16(program_number);
    w.u8(clear_code);
}

Result<ProgramAreaClear> ProgramAreaClear::decode(Bytes parameters) noexcept {
    if (auto ec = check_fixed(parameters, clear_size)) return Unexpected(ec);
    ByteReader r(parameters);
    ProgramAreaClear c;
    c.program_number = r.u16();
    c.clear_code = r.u8();
    return c;
}

Result<ProgramAreaClear::Response> ProgramAreaClear::decode_response(Bytes data) const {
    if (!data.empty()) return malformed();
    return EmptyResponse{};
}

}  // namespace fins
