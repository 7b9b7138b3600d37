// The value types a bridge tag can have are the value formats of src/typed (`fins --as`,
// the web API's `as`): int16 ... bcd32, string, and bool (Format::bits) for a single bit
// or a T/C/TK flag. Names, sizes, ranges and the word <-> JSON conversions live there;
// this adds what only the bridge has: a tag's value as kept between polls (with a
// string's text) and a write value checked against the tag's min/max.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "typed/value_format.hpp"

namespace fins::bridge {

using TagType = typed::Format;

// The types a tag may have (every format but hex): "bool" for bits.
std::optional<TagType> parse_tag_type(std::string_view name);
std::string_view tag_type_name(TagType t);
// "bool, int16, ..." for error messages.
std::string_view tag_type_names();
// Words the value occupies in the PLC (bool: the one word holding the bit).
std::size_t tag_words(TagType t, std::size_t string_length);

// A value as read: up to 4 words, or the characters of a string. Compared by value for
// "changed?" and turned into JSON without allocating for numbers.
struct TagValue {
    std::array<std::uint16_t, 4> words{};
    std::string text;  // string tags only
    bool operator==(const TagValue&) const = default;
};

// The value as a double (for deadbands); strings and non-BCD words give 0.
double numeric(TagType t, const TagValue& v);
// Appends the JSON form of the value (true, 12, 1.5, "abc") to out.
void append_json(std::string& out, TagType t, const TagValue& v);
nlohmann::json to_json(TagType t, const TagValue& v);

// A write value from a command: the words to write, or why it is refused (wrong JSON
// type, out of the type's range, outside [min, max] of the tag).
struct Encoded {
    std::array<std::uint16_t, 4> words{};
    std::size_t count = 0;
    std::string text;  // string tags: the characters (words via string_to_words)
    bool bit = false;  // boolean
};
struct Range {
    std::optional<double> min;
    std::optional<double> max;
};
std::optional<std::string> encode_value(TagType t, std::size_t string_length, const Range& range,
                                        const nlohmann::json& value, Encoded& out);

}  // namespace fins::bridge
