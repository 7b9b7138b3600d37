// Typed values <-> PLC words (contract in fins/values.hpp).
#include "fins/values.hpp"

#include <bit>

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

Result<std::vector<std::uint16_t>> string_to_words(std::string_view s) {
    return string_to_words(s, (s.size() + 1) / 2);
}

Result<std::vector<std::uint16_t>> string_to_words(std::string_view s, std::size_t word_count) {
    if (s.size() > word_count * 2) return invalid();
    std::vector<std::uint16_t> out(word_count, 0);
    for (std::size_t i = 0; i < s.size(); ++i) {
        const auto c = static_cast<unsigned char>(s[i]);
        if (c == 0 || c > 0x7F) return invalid();
        // The first character of each pair goes to the high byte (W342 5-2-1 word layout).
        const unsigned shift = (i % 2 == 0) ? 8u : 0u;
        out[i / 2] = static_cast<std::uint16_t>(out[i / 2] | (c << shift));
    }
    return out;
}

std::string words_to_string(Words w) {
    std::string out;
    out.reserve(w.size() * 2);
    for (const auto word : w) {
        for (const unsigned shift : {8u, 0u}) {
            const auto c = static_cast<char>((word >> shift) & 0xFF);
            if (c == '\0') return out;
            out.push_back(c);
        }
    }
    return out;
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
