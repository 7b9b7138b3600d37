// Typed values <-> PLC words (contract in fins/values.hpp).
#include "fins/values.hpp"

#include <bit>

#include <fmt/format.h>

namespace fins {
namespace {

Unexpected invalid() {
    return Unexpected(make_error_code(ClientError::invalid_argument));
}

constexpr std::uint16_t low(std::uint32_t v) noexcept {
    return static_cast<std::uint16_t>(v);
}
constexpr std::uint16_t high(std::uint32_t v) noexcept {
    return static_cast<std::uint16_t>(v >> 16);
}
constexpr std::uint32_t join(std::uint16_t lo, std::uint16_t hi) noexcept {
    return (std::uint32_t{hi} << 16) | lo;
}

// Four decimal digits into one BCD word; v must be below 10000.
constexpr std::uint16_t to_bcd(std::uint32_t v) noexcept {
    std::uint32_t out = 0;
    for (unsigned shift = 0; shift < 16; shift += 4) {
        out |= (v % 10) << shift;
        v /= 10;
    }
    return static_cast<std::uint16_t>(out);
}

// One BCD word back to 0-9999; -1 when a nibble is not a decimal digit.
constexpr std::int32_t from_bcd(std::uint16_t w) noexcept {
    std::int32_t v = 0;
    for (int shift = 12; shift >= 0; shift -= 4) {
        const int digit = (w >> shift) & 0xF;
        if (digit > 9) return -1;
        v = v * 10 + digit;
    }
    return v;
}

// The code point starting at text[at], advancing `at` past it; nullopt (at unchanged) for
// a byte that does not start a well-formed UTF-8 sequence: a stray continuation byte, a
// truncated sequence, an overlong form, a surrogate, or beyond U+10FFFF (RFC 3629).
std::optional<char32_t> next_code_point(std::string_view text, std::size_t& at) {
    const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
    const unsigned lead = byte(at);
    if (lead < 0x80) {
        ++at;
        return static_cast<char32_t>(lead);
    }
    // The sequence's length from its lead byte, the lead's payload bits, and the smallest
    // code point that needs that length (a smaller one is an overlong form).
    std::size_t length = 4;
    std::uint32_t c = lead & 0x07u;
    std::uint32_t min = 0x10000;
    if ((lead & 0xE0u) == 0xC0u) {
        length = 2;
        c = lead & 0x1Fu;
        min = 0x80;
    } else if ((lead & 0xF0u) == 0xE0u) {
        length = 3;
        c = lead & 0x0Fu;
        min = 0x800;
    } else if ((lead & 0xF8u) != 0xF0u) {
        return std::nullopt;
    }
    if (text.size() - at < length) return std::nullopt;
    for (std::size_t i = 1; i < length; ++i) {
        const unsigned next = byte(at + i);
        if ((next & 0xC0) != 0x80) return std::nullopt;
        c = (c << 6) | (next & 0x3Fu);
    }
    if (c < min || c > 0x10FFFF || (c >= 0xD800 && c <= 0xDFFF)) return std::nullopt;
    at += length;
    return static_cast<char32_t>(c);
}

}  // namespace

std::array<std::uint16_t, 1> int16_to_words(std::int16_t v) noexcept {
    return {static_cast<std::uint16_t>(v)};
}
std::array<std::uint16_t, 1> uint16_to_words(std::uint16_t v) noexcept {
    return {v};
}
std::array<std::uint16_t, 2> int32_to_words(std::int32_t v) noexcept {
    return uint32_to_words(static_cast<std::uint32_t>(v));
}
std::array<std::uint16_t, 2> uint32_to_words(std::uint32_t v) noexcept {
    return {low(v), high(v)};
}
std::array<std::uint16_t, 2> float_to_words(float v) noexcept {
    return uint32_to_words(std::bit_cast<std::uint32_t>(v));
}
std::array<std::uint16_t, 4> double_to_words(double v) noexcept {
    const auto bits = std::bit_cast<std::uint64_t>(v);
    return {static_cast<std::uint16_t>(bits), static_cast<std::uint16_t>(bits >> 16),
            static_cast<std::uint16_t>(bits >> 32), static_cast<std::uint16_t>(bits >> 48)};
}

Result<std::int16_t> words_to_int16(Words w) noexcept {
    if (w.size() != 1) return invalid();
    return static_cast<std::int16_t>(w[0]);
}
Result<std::uint16_t> words_to_uint16(Words w) noexcept {
    if (w.size() != 1) return invalid();
    return w[0];
}
Result<std::int32_t> words_to_int32(Words w) noexcept {
    if (w.size() != 2) return invalid();
    return static_cast<std::int32_t>(join(w[0], w[1]));
}
Result<std::uint32_t> words_to_uint32(Words w) noexcept {
    if (w.size() != 2) return invalid();
    return join(w[0], w[1]);
}
Result<float> words_to_float(Words w) noexcept {
    if (w.size() != 2) return invalid();
    return std::bit_cast<float>(join(w[0], w[1]));
}
Result<double> words_to_double(Words w) noexcept {
    if (w.size() != 4) return invalid();
    std::uint64_t bits = 0;
    for (std::size_t i = 4; i-- > 0;)
        bits = (bits << 16) | w[i];
    return std::bit_cast<double>(bits);
}

Result<std::array<std::uint16_t, 1>> bcd16_to_words(std::uint16_t v) noexcept {
    if (v > 9999) return invalid();
    return std::array<std::uint16_t, 1>{to_bcd(v)};
}
Result<std::array<std::uint16_t, 2>> bcd32_to_words(std::uint32_t v) noexcept {
    if (v > 99999999) return invalid();
    return std::array<std::uint16_t, 2>{to_bcd(v % 10000), to_bcd(v / 10000)};
}
Result<std::uint16_t> words_to_bcd16(Words w) noexcept {
    if (w.size() != 1) return invalid();
    const auto v = from_bcd(w[0]);
    if (v < 0) return invalid();
    return static_cast<std::uint16_t>(v);
}
Result<std::uint32_t> words_to_bcd32(Words w) noexcept {
    if (w.size() != 2) return invalid();
    const auto lo = from_bcd(w[0]);
    const auto hi = from_bcd(w[1]);
    if (lo < 0 || hi < 0) return invalid();
    return static_cast<std::uint32_t>(hi) * 10000 + static_cast<std::uint32_t>(lo);
}

Result<std::vector<std::uint16_t>> string_to_words(std::string_view utf8) {
    const auto bytes = utf8_to_latin1(utf8);
    if (!bytes) return invalid();
    return string_to_words(utf8, (bytes->size() + 1) / 2);
}

Result<std::vector<std::uint16_t>> string_to_words(std::string_view utf8, std::size_t word_count) {
    const auto bytes = utf8_to_latin1(utf8);
    if (!bytes || bytes->size() > word_count * 2) return invalid();
    std::vector<std::uint16_t> out(word_count, 0);
    for (std::size_t i = 0; i < bytes->size(); ++i) {
        const auto c = static_cast<unsigned char>((*bytes)[i]);
        if (c == 0) return invalid();
        // The first character of each pair goes to the high byte (W342 5-2-1 word layout).
        const unsigned shift = (i % 2 == 0) ? 8u : 0u;
        out[i / 2] = static_cast<std::uint16_t>(out[i / 2] | (c << shift));
    }
    return out;
}

std::string words_to_string(Words w) {
    std::string bytes;
    bytes.reserve(w.size() * 2);
    for (const auto word : w) {
        for (const unsigned shift : {8u, 0u}) {
            const auto c = static_cast<char>((word >> shift) & 0xFF);
            if (c == '\0') return latin1_to_utf8(bytes);
            bytes.push_back(c);
        }
    }
    return latin1_to_utf8(bytes);
}

std::optional<std::string> utf8_to_latin1(std::string_view utf8) {
    std::string out;
    out.reserve(utf8.size());
    std::size_t at = 0;
    while (at < utf8.size()) {
        const auto c = next_code_point(utf8, at);
        if (!c || *c > 0xFF) return std::nullopt;
        out.push_back(static_cast<char>(*c));
    }
    return out;
}

std::string latin1_to_utf8(std::string_view bytes) {
    std::string out;
    out.reserve(bytes.size() * 2);
    for (const char ch : bytes) {
        const auto c = static_cast<unsigned char>(ch);
        if (c < 0x80) {
            out.push_back(ch);
        } else {
            // U+0080-U+00FF: 110000xx 10xxxxxx (C2 or C3, then the low six bits).
            out.push_back(static_cast<char>(0xC0 | (c >> 6)));
            out.push_back(static_cast<char>(0x80 | (c & 0x3F)));
        }
    }
    return out;
}

std::optional<std::string> string_problem(std::string_view utf8) {
    std::size_t at = 0;
    for (std::size_t n = 1; at < utf8.size(); ++n) {
        const std::size_t start = at;
        const auto c = next_code_point(utf8, at);
        if (!c)
            return fmt::format("byte {} (0x{:02X}) is not UTF-8: text must be UTF-8", start + 1,
                               static_cast<unsigned char>(utf8[start]));
        if (*c == 0)
            return fmt::format("character {} is U+0000, which would end the string in PLC "
                               "memory (00 ends a string)",
                               n);
        if (*c > 0xFF)
            return fmt::format("character {} is U+{:04X}, above U+00FF: a PLC byte holds "
                               "one character U+0000-U+00FF (Latin-1)",
                               n, static_cast<std::uint32_t>(*c));
    }
    return std::nullopt;
}
std::vector<std::uint8_t> words_to_bytes(Words w) {
    std::vector<std::uint8_t> out;
    out.reserve(w.size() * 2);
    for (const auto word : w) {
        out.push_back(static_cast<std::uint8_t>(word >> 8));
        out.push_back(static_cast<std::uint8_t>(word));
    }
    return out;
}

Result<std::vector<std::uint16_t>> bytes_to_words(Bytes b) {
    if (b.size() % 2 != 0) return invalid();
    std::vector<std::uint16_t> out;
    out.reserve(b.size() / 2);
    for (std::size_t i = 0; i < b.size(); i += 2)
        out.push_back(static_cast<std::uint16_t>((b[i] << 8) | b[i + 1]));
    return out;
}

}  // namespace fins
