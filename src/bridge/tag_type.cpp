#include "bridge/tag_type.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "fins/values.hpp"

namespace fins::bridge {

namespace {

struct TypeRow {
    TagType type;
    std::string_view name;
    std::size_t words;
};

constexpr TypeRow rows[] = {
    {TagType::boolean, "bool", 1},   {TagType::int16, "int16", 1},   {TagType::uint16, "uint16", 1},
    {TagType::int32, "int32", 2},    {TagType::uint32, "uint32", 2}, {TagType::float32, "float", 2},
    {TagType::float64, "double", 4}, {TagType::bcd, "bcd", 1},       {TagType::bcd32, "bcd32", 2},
    {TagType::string, "string", 0},
};

std::span<const std::uint16_t> span_of(const TagValue& v, std::size_t n) {
    return {v.words.data(), n};
}

// The integer range of a type, or nullopt for floating point and strings.
std::optional<std::pair<double, double>> integer_range(TagType t) {
    switch (t) {
        case TagType::int16:
            return std::pair{-32768.0, 32767.0};
        case TagType::uint16:
            return std::pair{0.0, 65535.0};
        case TagType::int32:
            return std::pair{-2147483648.0, 2147483647.0};
        case TagType::uint32:
            return std::pair{0.0, 4294967295.0};
        case TagType::bcd:
            return std::pair{0.0, 9999.0};
        case TagType::bcd32:
            return std::pair{0.0, 99999999.0};
        default:
            return std::nullopt;
    }
}

template <class A>
void put(Encoded& out, const A& words) {
    out.count = words.size();
    for (std::size_t i = 0; i < words.size(); ++i)
        out.words[i] = words[i];
}

}  // namespace

std::optional<TagType> parse_tag_type(std::string_view name) {
    for (const auto& r : rows)
        if (r.name == name) return r.type;
    return std::nullopt;
}

std::string_view tag_type_name(TagType t) {
    for (const auto& r : rows)
        if (r.type == t) return r.name;
    return "?";
}

std::string_view tag_type_names() {
    return "bool, int16, uint16, int32, uint32, float, double, bcd, bcd32 or string";
}

std::size_t tag_words(TagType t, std::size_t string_length) {
    if (t == TagType::string) return (string_length + 1) / 2;
    for (const auto& r : rows)
        if (r.type == t) return r.words;
    return 1;
}

double numeric(TagType t, const TagValue& v) {
    switch (t) {
        case TagType::boolean:
            return v.words[0] != 0 ? 1.0 : 0.0;
        case TagType::int16:
            return words_to_int16(span_of(v, 1)).value_or(0);
        case TagType::uint16:
            return v.words[0];
        case TagType::int32:
            return words_to_int32(span_of(v, 2)).value_or(0);
        case TagType::uint32:
            return words_to_uint32(span_of(v, 2)).value_or(0);
        case TagType::float32:
            return static_cast<double>(words_to_float(span_of(v, 2)).value_or(0));
        case TagType::float64:
            return words_to_double(span_of(v, 4)).value_or(0);
        case TagType::bcd:
            return words_to_bcd16(span_of(v, 1)).value_or(0);
        case TagType::bcd32:
            return words_to_bcd32(span_of(v, 2)).value_or(0);
        case TagType::string:
            return 0;
    }
    return 0;
}

void append_json(std::string& out, TagType t, const TagValue& v) {
    auto it = std::back_inserter(out);
    switch (t) {
        case TagType::boolean:
            out += v.words[0] != 0 ? "true" : "false";
            return;
        case TagType::int16:
            fmt::format_to(it, "{}", static_cast<std::int16_t>(v.words[0]));
            return;
        case TagType::uint16:
            fmt::format_to(it, "{}", v.words[0]);
            return;
        case TagType::int32:
            fmt::format_to(it, "{}", words_to_int32(span_of(v, 2)).value_or(0));
            return;
        case TagType::uint32:
            fmt::format_to(it, "{}", words_to_uint32(span_of(v, 2)).value_or(0));
            return;
        case TagType::float32:
        case TagType::float64: {
            const double d = numeric(t, v);
            // JSON has no NaN or infinity: a PLC word pattern that is one is published null.
            if (!std::isfinite(d))
                out += "null";
            else if (t == TagType::float32)
                fmt::format_to(it, "{}", static_cast<float>(d));
            else
                fmt::format_to(it, "{}", d);
            return;
        }
        case TagType::bcd: {
            auto r = words_to_bcd16(span_of(v, 1));
            if (r)
                fmt::format_to(it, "{}", *r);
            else
                out += "null";
            return;
        }
        case TagType::bcd32: {
            auto r = words_to_bcd32(span_of(v, 2));
            if (r)
                fmt::format_to(it, "{}", *r);
            else
                out += "null";
            return;
        }
        case TagType::string:
            out += nlohmann::json(v.text).dump();
            return;
    }
}

nlohmann::json to_json(TagType t, const TagValue& v) {
    std::string s;
    append_json(s, t, v);
    return nlohmann::json::parse(s);
}

std::optional<std::string> encode_value(TagType t, std::size_t string_length, const Range& range,
                                        const nlohmann::json& value, Encoded& out) {
    const auto name = tag_type_name(t);
    if (t == TagType::string) {
        if (!value.is_string()) return fmt::format("{} needs a JSON string", name);
        const auto& s = value.get_ref<const std::string&>();
        if (s.size() > string_length)
            return fmt::format("string of {} characters is longer than the tag's {}", s.size(),
                               string_length);
        if (!string_to_words(s)) return "string must be ASCII (01-7F)";
        out.text = s;
        return std::nullopt;
    }
    if (t == TagType::boolean) {
        if (value.is_boolean())
            out.bit = value.get<bool>();
        else if (value.is_number_integer() &&
                 (value.get<std::int64_t>() == 0 || value.get<std::int64_t>() == 1))
            out.bit = value.get<std::int64_t>() == 1;
        else
            return "bool needs true, false, 0 or 1";
        out.count = 1;
        out.words[0] = out.bit ? 1 : 0;
        return std::nullopt;
    }
    if (!value.is_number()) return fmt::format("{} needs a JSON number", name);
    const double d = value.get<double>();
    if (auto r = integer_range(t)) {
        if (!value.is_number_integer())
            return fmt::format("{} needs an integer, not {}", name, value.dump());
        if (d < r->first || d > r->second)
            return fmt::format("{} is out of range for {} ({} to {})", value.dump(), name, r->first,
                               r->second);
    } else if (t == TagType::float32 && std::abs(d) > std::numeric_limits<float>::max()) {
        return fmt::format("{} is out of range for float", value.dump());
    }
    if (range.min && d < *range.min)
        return fmt::format("{} is below the tag's minimum {}", value.dump(), *range.min);
    if (range.max && d > *range.max)
        return fmt::format("{} is above the tag's maximum {}", value.dump(), *range.max);
    switch (t) {
        case TagType::int16:
            put(out, int16_to_words(value.get<std::int16_t>()));
            break;
        case TagType::uint16:
            put(out, uint16_to_words(value.get<std::uint16_t>()));
            break;
        case TagType::int32:
            put(out, int32_to_words(value.get<std::int32_t>()));
            break;
        case TagType::uint32:
            put(out, uint32_to_words(value.get<std::uint32_t>()));
            break;
        case TagType::float32:
            put(out, float_to_words(static_cast<float>(d)));
            break;
        case TagType::float64:
            put(out, double_to_words(d));
            break;
        case TagType::bcd:
            put(out, *bcd16_to_words(value.get<std::uint16_t>()));
            break;
        case TagType::bcd32:
            put(out, *bcd32_to_words(value.get<std::uint32_t>()));
            break;
        default:
            break;
    }
    return std::nullopt;
}

}  // namespace fins::bridge
