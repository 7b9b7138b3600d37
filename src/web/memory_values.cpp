// Typed reads and writes of I/O memory (contract in memory_values.hpp).
#include "web/memory_values.hpp"

#include <variant>
#include <vector>

#include <fmt/core.h>

#include "plc/io_memory.hpp"

namespace fins::web {

namespace {

using Json = nlohmann::json;
using typed::Format;

ApiError bad(std::string message) {
    return ApiError{400, std::move(message)};
}

// Which element kind an address and format mean, with the CLI's rules (cli/fins/commands.cpp
// run_read/run_write); `write` applies the write side's stricter ones.
ApiResult<ValueQuery> classify(std::string_view address, std::string_view as, bool write) {
    ValueQuery q;
    q.address_text = std::string(address);
    q.as = as.empty() ? "uint16" : std::string(as);
    auto start = parse_address(address);
    if (!start) return tl::unexpected(bad(fmt::format("{}: {}", address, start.error().message())));
    auto format = typed::parse_format(q.as);
    if (!format)
        return tl::unexpected(
            bad(fmt::format("as={}: not a format (uint16, int16, uint32, int32, float, double, "
                            "bcd, bcd32, hex, bits, "
                            "ascii, bool)",
                            q.as)));
    q.start = *start;
    q.format = *format;
    const Format f = *format;
    const bool flag_area = start->area == Area::timer || start->area == Area::counter;
    const bool bit_only = start->area == Area::task_flag;
    q.bits = f == Format::bits || ((start->bit || bit_only) && f == Format::uint16);
    if ((start->bit || bit_only) && !q.bits)
        return tl::unexpected(bad(fmt::format("{} names a bit: use as=bits", address)));
    if (q.bits && !start->bit && !bit_only && (write || !flag_area)) {
        if (start->area == Area::index_register || start->area == Area::data_register)
            return tl::unexpected(
                bad(fmt::format("{} has no bits: IR and DR are word access only", address)));
        return tl::unexpected(bad(fmt::format("{} is a word: name a bit ({}.00) for bits", address,
                                              format_address(*start))));
    }
    q.wide = start->area == Area::index_register;
    if (q.wide && write)
        return tl::unexpected(
            bad(fmt::format("{} is a 32-bit index register: writes take word areas", address)));
    if (q.wide && f != Format::uint16 && f != Format::uint32 && f != Format::int32 &&
        f != Format::hex)
        return tl::unexpected(bad(
            fmt::format("{} is a 32-bit index register: use as=uint32, int32 or hex", address)));
    auto mem = to_memory_address(*start, q.bits ? Access::bit : Access::word);
    if (!mem) return tl::unexpected(bad(fmt::format("{}: {}", address, mem.error().message())));
    q.memory = *mem;
    return q;
}

ApiResult<plc::ElementRange> locate(const plc::IoMemory& memory, const ValueQuery& q,
                                    std::size_t elements, AreaUse use, plc::Intent intent) {
    auto range = memory.locate(q.memory, static_cast<std::uint32_t>(elements), use, intent);
    if (!range)
        return tl::unexpected(bad(fmt::format("{} ({} {}): {}", q.address_text, elements,
                                              q.bits ? "bits" : "words", range.error().message())));
    return *range;
}

std::string as_text(const Json& v) {
    if (v.is_string()) return v.get<std::string>();
    if (v.is_boolean()) return v.get<bool>() ? "1" : "0";
    return v.dump();
}

}  // namespace

ApiResult<ValueQuery> make_query(const plc::IoMemory& memory, std::string_view address,
                                 std::size_t count, std::string_view as) {
    auto q = classify(address, as, false);
    if (!q) return q;
    if (count == 0 || count > max_values_per_read)
        return tl::unexpected(
            bad(fmt::format("count {}: 1 to {} values", count, max_values_per_read)));
    q->count = count;
    q->elements = q->bits || q->wide || q->format == Format::string
                      ? count
                      : count * typed::words_per_value(q->format);
    if (auto r = locate(memory, *q, q->elements, use_read, plc::Intent::read); !r)
        return tl::unexpected(r.error());
    if (q->bits)
        q->as = "bits";
    else
        q->as = std::string(typed::format_name(q->format));
    return q;
}

ApiResult<void> read_raw(const plc::IoMemory& memory, const ValueQuery& q,
                         std::chrono::system_clock::time_point now,
                         std::vector<std::uint8_t>& raw) {
    auto range = locate(memory, q, q.elements, use_read, plc::Intent::read);
    if (!range) return tl::unexpected(range.error());
    raw.resize(range->byte_size());
    ByteWriter out(raw);
    memory.read(*range, out, now);
    return {};
}

ApiResult<Json> read_values(const plc::IoMemory& memory, const ValueQuery& q,
                            std::chrono::system_clock::time_point now) {
    std::vector<std::uint8_t> data;
    if (auto r = read_raw(memory, q, now, data); !r) return tl::unexpected(r.error());
    return decode_values(q, data);
}

ApiResult<Json> decode_values(const ValueQuery& q, const std::vector<std::uint8_t>& data) {
    Json values = Json::array();
    const std::size_t size = data.size() / std::max<std::size_t>(q.elements, 1);
    if (size == 0 || data.size() != size * q.elements) return tl::unexpected(bad("no data"));
    if (q.bits) {
        for (std::size_t i = 0; i < q.elements; ++i)
            values.push_back((data[i * size + size - 1] & 1) != 0 ? 1 : 0);  // bit 1: forced
        return values;
    }
    if (q.wide) {
        for (std::size_t i = 0; i + 3 < data.size(); i += 4) {
            const std::uint32_t v = std::uint32_t{data[i]} << 24 |
                                    std::uint32_t{data[i + 1]} << 16 |
                                    std::uint32_t{data[i + 2]} << 8 | data[i + 3];
            if (q.format == Format::hex)
                values.push_back(fmt::format("0x{:08X}", v));
            else if (q.format == Format::int32)
                values.push_back(static_cast<std::int32_t>(v));
            else
                values.push_back(v);
        }
        return values;
    }
    std::vector<std::uint16_t> words;
    words.reserve(data.size() / 2);
    for (std::size_t i = 0; i + 1 < data.size(); i += 2)
        words.push_back(static_cast<std::uint16_t>(data[i] << 8 | data[i + 1]));
    auto printed = typed::print_words(q.format, words);
    if (!printed) {
        for (std::size_t i = 0; i < words.size(); ++i) {
            const auto w = words[i];
            if ((w & 0xF) > 9 || (w >> 4 & 0xF) > 9 || (w >> 8 & 0xF) > 9 || (w >> 12) > 9)
                return tl::unexpected(
                    bad(fmt::format("word {} of {} holds 0x{:04X}, which is not BCD (use as=hex)",
                                    i, q.address_text, w)));
        }
        return tl::unexpected(bad(printed.error().message()));
    }
    for (auto& p : *printed)
        values.push_back(std::move(p.json));
    return values;
}

ApiResult<std::size_t> write_values(plc::IoMemory& memory, std::string_view address,
                                    const Json& values, std::string_view as) {
    auto q = classify(address, as, true);
    if (!q) return tl::unexpected(q.error());
    std::vector<std::string> texts;
    if (values.is_string() && q->format == Format::string) {
        texts.push_back(values.get<std::string>());
    } else if (values.is_array() && !values.empty() && values.size() <= max_values_per_read) {
        for (const auto& v : values) {
            if (!v.is_number() && !v.is_string() && !v.is_boolean())
                return tl::unexpected(bad(fmt::format(
                    "{} is not a value",
                    v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace))));
            texts.push_back(as_text(v));
        }
    } else {
        return tl::unexpected(
            bad(fmt::format("\"values\" must be an array of 1 to {} values{}", max_values_per_read,
                            q->format == Format::string ? " or a string" : "")));
    }
    auto parsed = typed::parse_words(q->bits ? Format::bits : q->format, texts);
    if (auto* e = std::get_if<typed::ParseError>(&parsed)) return tl::unexpected(bad(e->message));
    const auto& words = std::get<std::vector<std::uint16_t>>(parsed);
    auto range = locate(memory, *q, words.size(), use_write, plc::Intent::write);
    if (!range) return tl::unexpected(range.error());
    std::vector<std::uint8_t> data;
    data.reserve(range->byte_size());
    for (const auto w : words) {
        if (range->byte_size() == words.size()) {
            data.push_back(static_cast<std::uint8_t>(w & 1));
        } else {
            data.push_back(static_cast<std::uint8_t>(w >> 8));
            data.push_back(static_cast<std::uint8_t>(w));
        }
    }
    if (const EndCode code = memory.write(*range, data); code != EndCode{})
        return tl::unexpected(bad(fmt::format("{}: {}", address, make_error_code(code).message())));
    return words.size();
}

}  // namespace fins::web
