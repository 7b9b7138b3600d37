#include "bridge/tag_type.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "fins/values.hpp"

namespace fins::bridge {

std::optional<TagType> parse_tag_type(std::string_view name) {
    auto f = typed::parse_format(name);
    if (!f || *f == TagType::hex) return std::nullopt;
    return f;
}

std::string_view tag_type_name(TagType t) {
    return t == TagType::bits ? "bool" : typed::format_name(t);
}

std::string_view tag_type_names() {
    return "bool, int16, uint16, int32, uint32, float, double, bcd, bcd32 or string";
}

std::size_t tag_words(TagType t, std::size_t string_length) {
    if (t == TagType::string) return (string_length + 1) / 2;
    if (t == TagType::bits) return 1;
    return typed::words_per_value(t);
}

double numeric(TagType t, const TagValue& v) {
    if (t == TagType::string) return 0;
    return typed::to_number(t, v.words).value_or(0);
}

void append_json(std::string& out, TagType t, const TagValue& v) {
    if (t == TagType::string)
        // Read text is valid UTF-8 (words_to_string); replace is the last line of defence.
        out +=
            nlohmann::json(v.text).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    else
        typed::append_json(out, t, v.words);
}

nlohmann::json to_json(TagType t, const TagValue& v) {
    std::string s;
    append_json(s, t, v);
    return nlohmann::json::parse(s);
}

std::optional<std::string> encode_value(TagType t, std::size_t string_length, const Range& range,
                                        const nlohmann::json& value, Encoded& out) {
    if (t == TagType::string) {
        if (!value.is_string()) return "string needs a JSON string";
        const auto& s = value.get_ref<const std::string&>();
        // One byte a character, U+0001-U+00FF (Latin-1, fins/values.hpp).
        if (auto why = string_problem(s)) return fmt::format("string refused: {}", *why);
        const auto bytes = utf8_to_latin1(s);
        if (!bytes) return std::string("string refused: not Latin-1 text");
        if (bytes->size() > string_length)
            return fmt::format("string of {} characters is longer than the tag's {}", bytes->size(),
                               string_length);
        out.text = s;
        return std::nullopt;
    }
    if (auto bad = typed::json_to_words(t, value, out.words)) return bad;
    out.count = tag_words(t, 0);
    if (t == TagType::bits) {
        out.bit = out.words[0] != 0;
        return std::nullopt;
    }
    const double d = value.get<double>();
    if (range.min && d < *range.min)
        return fmt::format("{} is below the tag's minimum {}", value.dump(), *range.min);
    if (range.max && d > *range.max)
        return fmt::format("{} is above the tag's maximum {}", value.dump(), *range.max);
    return std::nullopt;
}

}  // namespace fins::bridge
