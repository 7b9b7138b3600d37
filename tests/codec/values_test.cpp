// Typed values <-> PLC words (fins/values.hpp).
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/values.hpp"

namespace fins {
namespace {

using W = std::vector<std::uint16_t>;

template <std::size_t N>
W vec(const std::array<std::uint16_t, N>& a) {
    return W(a.begin(), a.end());
}

TEST(Values, WordOrderLeastSignificantWordFirst) {
    EXPECT_EQ(vec(int32_to_words(0x12345678)), (W{0x5678, 0x1234}));
    EXPECT_EQ(vec(uint32_to_words(0xDEADBEEF)), (W{0xBEEF, 0xDEAD}));
    EXPECT_EQ(vec(int32_to_words(-2)), (W{0xFFFE, 0xFFFF}));
    EXPECT_EQ(vec(float_to_words(1.0f)), (W{0x0000, 0x3F80}));
    EXPECT_EQ(vec(float_to_words(-2.5f)), (W{0x0000, 0xC020}));
    // 1.0 = 3FF0 0000 0000 0000.
    EXPECT_EQ(vec(double_to_words(1.0)), (W{0x0000, 0x0000, 0x0000, 0x3FF0}));
    EXPECT_EQ(vec(double_to_words(0.1)), (W{0x999A, 0x9999, 0x9999, 0x3FB9}));
    EXPECT_EQ(vec(int16_to_words(-1)), (W{0xFFFF}));
    EXPECT_EQ(vec(uint16_to_words(0x1234)), (W{0x1234}));
    // On the wire each word is big-endian: int32 0x12345678 -> 56 78 12 34.
    EXPECT_EQ(words_to_bytes(int32_to_words(0x12345678)), test::hex("56 78 12 34"));
}

TEST(Values, RoundTrips) {
    for (std::int32_t v : {0, 1, -1, 0x12345678, std::numeric_limits<std::int32_t>::min(),
                           std::numeric_limits<std::int32_t>::max()}) {
        EXPECT_EQ(words_to_int32(int32_to_words(v)).value(), v);
    }
    for (std::uint32_t v : {0u, 1u, 0xFFFFFFFFu, 0x80000000u})
        EXPECT_EQ(words_to_uint32(uint32_to_words(v)).value(), v);
    for (std::int16_t v : {std::int16_t{0}, std::int16_t{-32768}, std::int16_t{32767}})
        EXPECT_EQ(words_to_int16(int16_to_words(v)).value(), v);
    EXPECT_EQ(words_to_uint16(uint16_to_words(65535)).value(), 65535);
    for (float v : {0.0f, -0.0f, 1.5f, 3.4e38f, -1e-38f})
        EXPECT_EQ(words_to_float(float_to_words(v)).value(), v);
    for (double v : {0.0, 0.1, -123456.789, 1e300})
        EXPECT_EQ(words_to_double(double_to_words(v)).value(), v);
    EXPECT_TRUE(std::isnan(words_to_float(W{0x0000, 0x7FC0}).value()));
    EXPECT_EQ(words_to_int32(W{0x5678, 0x1234}).value(), 0x12345678);
}

TEST(Values, WrongWordCounts) {
    const W none, one{1}, two{1, 2}, three{1, 2, 3}, four{1, 2, 3, 4};
    const auto bad = make_error_code(ClientError::invalid_argument);
    EXPECT_EQ(words_to_int16(none).error(), bad);
    EXPECT_EQ(words_to_uint16(two).error(), bad);
    EXPECT_EQ(words_to_int32(one).error(), bad);
    EXPECT_EQ(words_to_uint32(three).error(), bad);
    EXPECT_EQ(words_to_float(one).error(), bad);
    EXPECT_EQ(words_to_double(three).error(), bad);
    EXPECT_EQ(words_to_bcd16(two).error(), bad);
    EXPECT_EQ(words_to_bcd32(one).error(), bad);
    EXPECT_TRUE(words_to_double(four));
}

TEST(Values, Bcd) {
    EXPECT_EQ(vec(bcd16_to_words(1234).value()), (W{0x1234}));
    EXPECT_EQ(vec(bcd16_to_words(9999).value()), (W{0x9999}));
    EXPECT_EQ(vec(bcd16_to_words(0).value()), (W{0x0000}));
    EXPECT_EQ(bcd16_to_words(10000).error(), ClientError::invalid_argument);
    EXPECT_EQ(vec(bcd32_to_words(12345678).value()), (W{0x5678, 0x1234}));
    EXPECT_EQ(vec(bcd32_to_words(99999999).value()), (W{0x9999, 0x9999}));
    EXPECT_EQ(bcd32_to_words(100000000).error(), ClientError::invalid_argument);
    EXPECT_EQ(words_to_bcd16(W{0x0042}).value(), 42);
    EXPECT_EQ(words_to_bcd32(W{0x5678, 0x1234}).value(), 12345678u);
    for (std::uint16_t bad : std::array<std::uint16_t, 5>{0x000A, 0x00F0, 0x0B00, 0xC000, 0xFFFF})
        EXPECT_EQ(words_to_bcd16(W{bad}).error(), ClientError::invalid_argument) << bad;
    EXPECT_EQ(words_to_bcd32(W{0x0001, 0x1A00}).error(), ClientError::invalid_argument);
    EXPECT_EQ(words_to_bcd32(W{0x000F, 0x0000}).error(), ClientError::invalid_argument);
    for (std::uint32_t v = 0; v <= 9999; v += 7)
        EXPECT_EQ(words_to_bcd16(bcd16_to_words(static_cast<std::uint16_t>(v)).value()).value(), v);
}

TEST(Values, Strings) {
    // First character in the high byte; odd lengths padded with 00.
    EXPECT_EQ(string_to_words("ABC").value(), (W{0x4142, 0x4300}));
    EXPECT_EQ(string_to_words("AB").value(), (W{0x4142}));
    EXPECT_TRUE(string_to_words("").value().empty());
    EXPECT_EQ(string_to_words("AB", 3).value(), (W{0x4142, 0x0000, 0x0000}));
    EXPECT_EQ(string_to_words("ABCDE", 2).error(), ClientError::invalid_argument);
    EXPECT_EQ(string_to_words(std::string_view("A\0B", 3)).error(), ClientError::invalid_argument);
    // UTF-8 in, one byte a character (Latin-1): é is U+00E9, byte E9.
    EXPECT_EQ(string_to_words("caf\xC3\xA9").value(), (W{0x6361, 0x66E9}));
    EXPECT_EQ(string_to_words("\xC4\x80").error(), ClientError::invalid_argument);  // U+0100
    EXPECT_EQ(string_to_words("\xE9").error(), ClientError::invalid_argument);  // not UTF-8
    EXPECT_EQ(string_to_words("\xC3\xA9\xC3\xA9\xC3\xA9", 1).error(),
              ClientError::invalid_argument);  // 3 characters, 6 bytes of UTF-8: 2 words
    EXPECT_EQ(string_to_words("\xC3\xA9\xC3\xA9\xC3\xA9", 2).value(), (W{0xE9E9, 0xE900}));
    // Reading stops at the first 00 byte, wherever it is.
    EXPECT_EQ(words_to_string(W{0x4142, 0x4300}), "ABC");
    EXPECT_EQ(words_to_string(W{0x4142, 0x4344}), "ABCD");
    EXPECT_EQ(words_to_string(W{0x4100, 0x4344}), "A");
    EXPECT_EQ(words_to_string(W{0x0041}), "");
    EXPECT_EQ(words_to_string(W{}), "");
    EXPECT_EQ(words_to_string(string_to_words("HELLO PLC", 8).value()), "HELLO PLC");
}

// Issue 25: bytes 80-FF are text too. Each byte reads as the character of the same code
// point, in UTF-8, so the text is always valid UTF-8 and writing it back restores it.
TEST(Values, StringBytesAreLatin1) {
    EXPECT_EQ(words_to_string(W{0x41E1, 0x4243}), "A\xC3\xA1" "BC");  // Aá BC
    EXPECT_EQ(words_to_string(W{0xB043}), "\xC2\xB0" "C");             // °C
    EXPECT_EQ(words_to_string(W{0xFF80}), "\xC3\xBF\xC2\x80");
    // Every byte 01-FF, in both halves of a word: one character, and back to the same byte.
    for (unsigned b = 1; b <= 0xFF; ++b) {
        const auto word = static_cast<std::uint16_t>(b << 8 | b);
        const std::string text = words_to_string(W{word});
        EXPECT_EQ(text, latin1_to_utf8(std::string(2, static_cast<char>(b)))) << b;
        EXPECT_EQ(text.size(), b < 0x80 ? 2u : 4u) << b;
        EXPECT_EQ(string_to_words(text).value(), W{word}) << b;
        EXPECT_EQ(string_problem(text), std::nullopt) << b;
    }
    // Every word without a 00 byte: words -> text -> the same word.
    for (unsigned w = 0; w <= 0xFFFF; ++w) {
        if ((w & 0xFF) == 0 || (w >> 8) == 0) continue;
        const W words{static_cast<std::uint16_t>(w)};
        ASSERT_EQ(string_to_words(words_to_string(words)).value(), words) << w;
    }
}

TEST(Values, Latin1Conversions) {
    std::string all;
    for (unsigned b = 0; b <= 0xFF; ++b)
        all.push_back(static_cast<char>(b));
    const std::string utf8 = latin1_to_utf8(all);
    EXPECT_EQ(utf8.size(), 128u + 2 * 128u);
    EXPECT_EQ(utf8_to_latin1(utf8), all);  // all 256 byte values, 00 included
    EXPECT_EQ(utf8_to_latin1("\xC4\x80"), std::nullopt);          // U+0100
    EXPECT_EQ(utf8_to_latin1("\xE2\x82\xAC"), std::nullopt);      // U+20AC euro sign
    EXPECT_EQ(utf8_to_latin1("\xF0\x9F\x98\x80"), std::nullopt);  // U+1F600
    for (const std::string_view bad :
         {"\xB0", "\xC3", "\xC3(", "\xC1\xBF" /* overlong 7F */, "\xC0\x80" /* overlong 00 */,
          "\xED\xA0\x80" /* surrogate */, "\xF4\x90\x80\x80" /* above U+10FFFF */, "\xFF",
          "\xE0\x80\xAF" /* overlong / */})
        EXPECT_EQ(utf8_to_latin1(bad), std::nullopt) << bad.size();
}

TEST(Values, StringProblemsSayWhy) {
    EXPECT_EQ(string_problem("A\xC4\x80"),
              "character 2 is U+0100, above U+00FF: a PLC byte holds one character "
              "U+0000-U+00FF (Latin-1)");
    EXPECT_EQ(string_problem("AB\xE9"), "byte 3 (0xE9) is not UTF-8: text must be UTF-8");
    EXPECT_EQ(string_problem(std::string_view("A\0", 2)),
              "character 2 is U+0000, which would end the string in PLC memory (00 ends a "
              "string)");
    EXPECT_EQ(string_problem("\xC2\xB0" "C"), std::nullopt);
    EXPECT_EQ(string_problem(""), std::nullopt);
}

TEST(Values, BytesAndWords) {
    EXPECT_EQ(words_to_bytes(W{0x1234, 0xABCD}), test::hex("12 34 AB CD"));
    EXPECT_EQ(bytes_to_words(test::hex("12 34 AB CD")).value(), (W{0x1234, 0xABCD}));
    EXPECT_TRUE(bytes_to_words({}).value().empty());
    EXPECT_EQ(bytes_to_words(test::hex("12 34 AB")).error(), ClientError::invalid_argument);
    EXPECT_TRUE(words_to_bytes(W{}).empty());
}

}  // namespace
}  // namespace fins
