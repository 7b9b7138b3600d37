// Value formats (`fins --as`, the HTTP API's `as`, the WebSocket's subscriptions,
// fins-bridge's tag types): how words read from the PLC are printed and how text or JSON
// values become words. One table for every front end, so `fins read D100 --as int32`,
// `GET /api/read?...&as=int32` and a bridge tag of type int32 agree. Word order is
// Omron's (fins/values.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "fins/error.hpp"
#include "fins/values.hpp"

namespace fins::typed {

enum class Format : std::uint8_t {
    int16,
    uint16,
    int32,
    uint32,
    float32,  // "float"
    float64,  // "double"
    bcd,      // one word, 0-9999
    bcd32,    // two words, 0-99999999
    string,   // two characters a word
    bits,     // "bool" also: one bit
    hex,      // one word, printed 0x1234
};

// Every format, in the table's order (int16 first).
std::span<const Format> all_formats() noexcept;
// Also takes "float32", "float64", "ascii" (string) and "bool" (bits).
std::optional<Format> parse_format(std::string_view name);
std::string_view format_name(Format f);
// Words per value; 0 for bits (one element per value).
std::size_t words_per_value(Format f);

// A printed value: text for humans, JSON for --json.
struct Printed {
    std::string text;
    nlohmann::json json;
};

// Words -> values. `words.size()` is a multiple of words_per_value(f) (bits: one word a
// value, the bit as word 0, nonzero = 1); for string the
// whole run is one value.
Result<std::vector<Printed>> print_words(Format f, const std::vector<std::uint16_t>& words);
// Command-line values -> words, with a readable error for the first bad one.
struct ParseError {
    std::string message;
};
std::variant<std::vector<std::uint16_t>, ParseError> parse_words(
    Format f, const std::vector<std::string>& values);
// "1", "0", "on", "off", "true", "false" -> bit.
std::optional<bool> parse_bit(std::string_view s);

// One value without allocating (fins-bridge's hot path): `words` holds
// words_per_value(f) words (bits: the bit as word 0). Not for string.
// The integer range of the format (bits 0-1), or nullopt for float, double and string.
std::optional<std::pair<double, double>> integer_range(Format f) noexcept;
// As a number (deadbands): nullopt for a word pattern that is not BCD, and for string.
std::optional<double> to_number(Format f, Words words) noexcept;
// Appends the value as JSON: true/false, an integer, a number; null for what JSON cannot
// carry (NaN, infinity) and for a word pattern that is not BCD.
void append_json(std::string& out, Format f, Words words);
// A JSON value (true/false or 0/1 for bits, an integer for the integer formats, a number
// for float and double) into `words` (words_per_value(f) of them, bits: one), checked
// against the format's range. The reason when it does not fit. Not for string.
std::optional<std::string> json_to_words(Format f, const nlohmann::json& value,
                                         std::array<std::uint16_t, 4>& words);

}  // namespace fins::typed
