// The value types a bridge tag can have: the names of `fins --as` (int16 ... string) plus
// bool for a single bit or a T/C/TK flag. Words are converted with libfins' values.hpp
// (Omron word order, least significant word first), the one place that knows it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

namespace fins::bridge {

enum class TagType : std::uint8_t {
    boolean,  // "bool": a bit (CIO0.00) or a completion/task flag (T5, TK2)
    int16,
    uint16,
    int32,
    uint32,
    float32,  // "float"
    float64,  // "double"
    bcd,      // one word, 0-9999
    bcd32,    // two words, 0-99999999
    string,   // `length` characters, two a word
};

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

// The value as a double (for deadbands); strings give 0.
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
