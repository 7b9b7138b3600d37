// Value formats (`fins --as`, the HTTP API's `as`, the WebSocket's subscriptions): how
// words read from the PLC are printed and how text values become words. One table for
// every front end, so `fins read D100 --as int32` and `GET /api/read?...&as=int32` agree.
// Word order is Omron's (fins/values.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "fins/error.hpp"

namespace fins::typed {

enum class Format { int16, uint16, int32, uint32, float32, float64, bcd, string, bits, hex };

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

// Words -> values. `words.size()` is a multiple of words_per_value(f); for string the
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

}  // namespace fins::typed
