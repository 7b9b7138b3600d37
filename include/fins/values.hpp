// Typed values <-> PLC words, in Omron's word order.
//
// A "word" here is the 16-bit value of one PLC word (the wire carries it big-endian, see
// words_to_bytes()). Multi-word values follow the CS/CJ convention used by the CPU
// Unit's 32/64-bit instructions: the least significant word sits at the lower address.
//   int32 0x12345678      -> {0x5678, 0x1234}
//   float 1.0f (3F800000) -> {0x0000, 0x3F80}
//   double                -> 4 words, least significant first
// BCD: one word holds 0-9999 (4 digits), two words 0-99999999 (low 4 digits first).
// Strings: two characters per word, the first in the high byte; an odd length is padded
// with 00; reading stops at the first 00 byte.
//
// Decoders take exactly the words the type needs; every failure (wrong word count,
// out-of-range value, bad BCD digit, non-ASCII character) is ClientError::invalid_argument.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"

namespace fins {

using Words = std::span<const std::uint16_t>;

std::array<std::uint16_t, 1> int16_to_words(std::int16_t v) noexcept;
std::array<std::uint16_t, 1> uint16_to_words(std::uint16_t v) noexcept;
std::array<std::uint16_t, 2> int32_to_words(std::int32_t v) noexcept;
std::array<std::uint16_t, 2> uint32_to_words(std::uint32_t v) noexcept;
std::array<std::uint16_t, 2> float_to_words(float v) noexcept;
std::array<std::uint16_t, 4> double_to_words(double v) noexcept;

Result<std::int16_t> words_to_int16(Words w) noexcept;    // exactly 1 word
Result<std::uint16_t> words_to_uint16(Words w) noexcept;  // exactly 1 word
Result<std::int32_t> words_to_int32(Words w) noexcept;    // exactly 2 words
Result<std::uint32_t> words_to_uint32(Words w) noexcept;  // exactly 2 words
Result<float> words_to_float(Words w) noexcept;           // exactly 2 words
Result<double> words_to_double(Words w) noexcept;         // exactly 4 words

// BCD (one decimal digit per nibble). Values above 9999 / 99999999 are refused.
Result<std::array<std::uint16_t, 1>> bcd16_to_words(std::uint16_t v) noexcept;
Result<std::array<std::uint16_t, 2>> bcd32_to_words(std::uint32_t v) noexcept;
// Nibbles A-F are refused.
Result<std::uint16_t> words_to_bcd16(Words w) noexcept;  // exactly 1 word
Result<std::uint32_t> words_to_bcd32(Words w) noexcept;  // exactly 2 words

// ASCII only (01-7F): 00 would end the string early and bytes above 7F are not ASCII.
Result<std::vector<std::uint16_t>> string_to_words(std::string_view s);
// Padded with 00 to exactly word_count words; refused when s needs more.
Result<std::vector<std::uint16_t>> string_to_words(std::string_view s, std::size_t word_count);
// Characters up to the first 00 byte (or the end of the words).
std::string words_to_string(Words w);

// Each word as two bytes, high byte first (the wire order of W342 5-2-1).
std::vector<std::uint8_t> words_to_bytes(Words w);
// Big-endian byte pairs to words; an odd byte count is refused.
Result<std::vector<std::uint16_t>> bytes_to_words(Bytes b);

}  // namespace fins
