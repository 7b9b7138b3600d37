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
// with 00; reading stops at the first 00 byte. A byte is the character of the same code
// point (ISO-8859-1, "Latin-1": 41 is "A", B0 is "°") and text is UTF-8, so each of the 256
// byte values reads as exactly one character, the text is always valid UTF-8, and writing
// it back restores the bytes.
//
// Decoders take exactly the words the type needs; every failure (wrong word count,
// out-of-range value, bad BCD digit, a character a byte cannot hold) is
// ClientError::invalid_argument.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
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

// UTF-8 text of characters U+0001-U+00FF, one byte each: U+0000 would end the string
// early, a character above U+00FF has no byte, and text that is not UTF-8 is refused
// (string_problem() says why).
Result<std::vector<std::uint16_t>> string_to_words(std::string_view utf8);
// Padded with 00 to exactly word_count words; refused when the text needs more.
Result<std::vector<std::uint16_t>> string_to_words(std::string_view utf8, std::size_t word_count);
// Characters up to the first 00 byte (or the end of the words), as UTF-8.
std::string words_to_string(Words w);

// The text's bytes (one per character, U+0000-U+00FF), or nullopt when it is not UTF-8 or
// holds a character above U+00FF.
std::optional<std::string> utf8_to_latin1(std::string_view utf8);
// Each byte as the character of the same code point, in UTF-8 (never invalid).
std::string latin1_to_utf8(std::string_view bytes);
// Why string_to_words refuses the characters of `utf8` (length aside): "byte 3 is not
// UTF-8", "U+0100 (character 2) is above U+00FF: ...", "U+0000 ..."; nullopt when it
// takes them. The sentence never quotes the text, so it is itself valid UTF-8.
std::optional<std::string> string_problem(std::string_view utf8);

// Each word as two bytes, high byte first (the wire order of W342 5-2-1).
std::vector<std::uint8_t> words_to_bytes(Words w);
// Big-endian byte pairs to words; an odd byte count is refused.
Result<std::vector<std::uint16_t>> bytes_to_words(Bytes b);

}  // namespace fins
