// Hexadecimal text, read in one place: the codec's ASCII framings (Host Link, Modbus ASCII),
// address strings, and the raw bytes the CLI and the control channel take.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace fins::hex {

// 0-15 for 0-9, A-F and a-f; -1 for anything else.
constexpr int digit_value(char c) noexcept {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    return -1;
}

// Two digits -> a byte (0-255), or -1.
constexpr int byte_value(char high, char low) noexcept {
    const int h = digit_value(high);
    const int l = digit_value(low);
    return h < 0 || l < 0 ? -1 : h * 16 + l;
}

// "0A 1b:FF" -> {0x0A, 0x1B, 0xFF}: pairs of digits, any of `separators` between or inside
// them ignored. Nothing for an odd number of digits or any other character.
inline std::optional<std::vector<std::uint8_t>> parse_bytes(std::string_view text,
                                                            std::string_view separators) {
    std::vector<std::uint8_t> out;
    out.reserve(text.size() / 2);
    int high = -1;
    for (const char c : text) {
        if (separators.find(c) != std::string_view::npos) continue;
        const int d = digit_value(c);
        if (d < 0) return std::nullopt;
        if (high < 0) {
            high = d;
        } else {
            out.push_back(static_cast<std::uint8_t>(high * 16 + d));
            high = -1;
        }
    }
    if (high >= 0) return std::nullopt;
    return out;
}

// Whether a number may be written with a "0x" (or "0X") before its digits.
enum class Prefix { none, optional };

// A number in hex digits alone ("1a"), or after "0x" where `prefix` allows ("0x1A"): its
// value, when there are 1 to `max_digits` (at most 16) digits. Nothing for "", "0x", a sign,
// a space or any other character.
constexpr std::optional<std::uint64_t> parse_number(std::string_view text,
                                                    std::size_t max_digits = 16,
                                                    Prefix prefix = Prefix::optional) noexcept {
    if (prefix == Prefix::optional && text.size() > 2 && text[0] == '0' &&
        (text[1] == 'x' || text[1] == 'X'))
        text.remove_prefix(2);
    if (text.empty() || text.size() > max_digits || text.size() > 16) return std::nullopt;
    std::uint64_t value = 0;
    for (const char c : text) {
        const int d = digit_value(c);
        if (d < 0) return std::nullopt;
        value = value * 16 + static_cast<std::uint64_t>(d);
    }
    return value;
}

}  // namespace fins::hex
