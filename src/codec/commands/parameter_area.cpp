// Parameter area commands 02 01 .. 02 03 (W342 5-3-7 .. 5-3-9, frames 6) and the
// parameter area table of 5-3-7.
//
// Server side (decode): errors are the end codes the CPU Unit answers, 1002 for a
// command shorter than its fixed part and 1001 for one longer than it.
// Client side (decode_response): any length or echo mismatch is malformed_response.
#include "fins/commands/parameter_area.hpp"
#include "codec/command_codec.hpp"
#include "codec/hex.hpp"

namespace fins {

using codec::check_fixed;
using codec::empty_response;
using codec::end_code;
using codec::malformed;

namespace {

// Parameter sizes (frames 6): area code, beginning word, number of words [, data].
constexpr std::size_t read_size = 6;
constexpr std::size_t write_fixed_size = 6;
constexpr std::size_t clear_size = 8;
constexpr std::size_t read_response_fixed_size = 6;

// W342 5-3-7 "Parameter Areas"; offsets inside 8000 as laid out in parameter_area.hpp.
constexpr ParameterAreaInfo areas[] = {
    {parameter_area_all, "all", "all parameter areas", parameter_area_all_words, 0x0000, true},
    {parameter_area_cpu_bus_unit_setup, "cpu-bus", "CPU Bus Unit setup", 5184, 0x0B00, true},
    {parameter_area_plc_setup, "plc-setup", "PLC Setup", 512, 0x0000, true},
    {parameter_area_io_table, "io-table", "I/O table registration", 1280, 0x0400, true},
    {parameter_area_routing_tables, "routing", "routing tables", 512, 0x0900, false},
};

std::uint16_t with_flag(std::uint16_t count, bool last) noexcept {
    return static_cast<std::uint16_t>((count & word_count_mask) | (last ? last_word_bit : 0));
}

}  // namespace

std::span<const ParameterAreaInfo> parameter_area_table() noexcept {
    return areas;
}

const ParameterAreaInfo* find_parameter_area(std::uint16_t code) noexcept {
    for (const auto& a : areas)
        if (a.code == code) return &a;
    return nullptr;
}

const ParameterAreaInfo* find_parameter_area(std::string_view text) noexcept {
    for (const auto& a : areas)
        if (a.id == text) return &a;
    if (text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X'))
        text.remove_prefix(2);
    if (text.size() != 4) return nullptr;
    const auto code = hex::parse_number(text, 4, hex::Prefix::none);
    return code ? find_parameter_area(static_cast<std::uint16_t>(*code)) : nullptr;
}

void ParameterAreaReadResponse::encode(ByteWriter& w) const noexcept {
    w.u16(area);
    w.u16(start);
    w.u16(with_flag(count, last_word));
    for (auto word : words)
        w.u16(word);
}

void ParameterAreaRead::encode(ByteWriter& w) const noexcept {
    w.u16(area);
    w.u16(start);
    w.u16(with_flag(count, last_word));
}

Result<ParameterAreaRead> ParameterAreaRead::decode(Bytes parameters) noexcept {
    if (auto ec = check_fixed(parameters, read_size)) return Unexpected(ec);
    ByteReader r(parameters);
    ParameterAreaRead c;
    c.area = r.u16();
    c.start = r.u16();
    const auto raw_count = r.u16();
    c.count = raw_count & word_count_mask;
    c.last_word = (raw_count & last_word_bit) != 0;
    return c;
}

Result<ParameterAreaRead::Response> ParameterAreaRead::decode_response(Bytes data) const {
    ByteReader r(data);
    Response response;
    response.area = r.u16();
    response.start = r.u16();
    const auto raw_count = r.u16();
    if (r.truncated() || data.size() < read_response_fixed_size) return malformed();
    response.count = raw_count & word_count_mask;
    response.last_word = (raw_count & last_word_bit) != 0;
    // A normal answer carries at most what was asked for (fewer only at the area's end,
    // which also sets bit 15).
    if (response.area != area || response.start != start || response.count > count)
        return malformed();
    if (r.remaining() != std::size_t{response.count} * 2) return malformed();
    response.words.reserve(response.count);
    for (std::uint16_t i = 0; i < response.count; ++i)
        response.words.push_back(r.u16());
    if (!r.complete()) return malformed();
    return response;
}

void ParameterAreaWrite::encode(ByteWriter& w) const noexcept {
    w.u16(area);
    w.u16(start);
    w.u16(with_flag(count, last_word));
    w.bytes(data);
}

Result<ParameterAreaWrite> ParameterAreaWrite::decode(Bytes parameters) noexcept {
    if (parameters.size() < write_fixed_size) return end_code(EndCode::command_too_short);
    ByteReader r(parameters);
    ParameterAreaWrite c;
    c.area = r.u16();
    c.start = r.u16();
    const auto raw_count = r.u16();
    c.count = raw_count & word_count_mask;
    c.last_word = (raw_count & last_word_bit) != 0;
    c.data = r.rest();
    return c;
}

Result<ParameterAreaWrite::Response> ParameterAreaWrite::decode_response(Bytes response) const {
    return empty_response(response);
}

void ParameterAreaClear::encode(ByteWriter& w) const noexcept {
    w.u16(area);
    w.u16(start);
    w.u16(with_flag(count, last_word));
    w.u16(value);
}

Result<ParameterAreaClear> ParameterAreaClear::decode(Bytes parameters) noexcept {
    if (auto ec = check_fixed(parameters, clear_size)) return Unexpected(ec);
    ByteReader r(parameters);
    ParameterAreaClear c;
    c.area = r.u16();
    c.start = r.u16();
    const auto raw_count = r.u16();
    c.count = raw_count & word_count_mask;
    c.last_word = (raw_count & last_word_bit) != 0;
    c.value = r.u16();
    return c;
}

Result<ParameterAreaClear::Response> ParameterAreaClear::decode_response(Bytes data) const {
    return empty_response(data);
}

}  // namespace fins
