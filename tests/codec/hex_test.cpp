// src/codec/hex.hpp: digits, byte pairs and hex numbers, the one place they are read.
#include "codec/hex.hpp"

#include <cstdint>
#include <optional>
#include <vector>

#include <gtest/gtest.h>

namespace fins::hex {
namespace {

TEST(Hex, DigitAndByteValues) {
    EXPECT_EQ(digit_value('0'), 0);
    EXPECT_EQ(digit_value('9'), 9);
    EXPECT_EQ(digit_value('a'), 10);
    EXPECT_EQ(digit_value('F'), 15);
    EXPECT_EQ(digit_value('g'), -1);
    EXPECT_EQ(digit_value(' '), -1);
    EXPECT_EQ(byte_value('1', 'b'), 0x1B);
    EXPECT_EQ(byte_value('1', 'x'), -1);
    static_assert(byte_value('F', 'F') == 0xFF);
}

TEST(Hex, BytesWithSeparators) {
    EXPECT_EQ(parse_bytes("0A 1b:FF", " :"), (std::vector<std::uint8_t>{0x0A, 0x1B, 0xFF}));
    // A separator inside a pair is ignored too ("0 A" is 0A), as the CLI's hex files.
    EXPECT_EQ(parse_bytes("0 A\n1\t2", " \t\n"), (std::vector<std::uint8_t>{0x0A, 0x12}));
    EXPECT_EQ(parse_bytes("", " "), std::vector<std::uint8_t>{});
    EXPECT_EQ(parse_bytes("0A1", " "), std::nullopt);    // odd
    EXPECT_EQ(parse_bytes("0A-1B", " "), std::nullopt);  // not a separator
}

TEST(Hex, NumberWithOrWithoutPrefix) {
    EXPECT_EQ(parse_number("1a"), 0x1Au);
    EXPECT_EQ(parse_number("0x1A"), 0x1Au);
    EXPECT_EQ(parse_number("0XfF"), 0xFFu);
    EXPECT_EQ(parse_number("0"), 0u);
    EXPECT_EQ(parse_number("00"), 0u);
    EXPECT_EQ(parse_number("FFFFFFFFFFFFFFFF"), 0xFFFFFFFFFFFFFFFFu);
    static_assert(*parse_number("0x8000") == 0x8000);
}

TEST(Hex, NumberRefusals) {
    for (const char* bad : {"", "0x", "0X", "x1", "+1", "-1", " 1", "1 ", "1G", "0x0x1",
                            "11111111111111111"})  // 17 digits
        EXPECT_EQ(parse_number(bad), std::nullopt) << bad;
}

TEST(Hex, NumberDigitLimit) {
    // A 16-bit code: 1-4 digits (after any 0x).
    EXPECT_EQ(parse_number("FFFF", 4), 0xFFFFu);
    EXPECT_EQ(parse_number("0xFFFF", 4), 0xFFFFu);
    EXPECT_EQ(parse_number("0FFFF", 4), std::nullopt);
    EXPECT_EQ(parse_number("0x10000", 4), std::nullopt);
}

TEST(Hex, NumberWithoutPrefixAllowed) {
    // scuN.P: N is a digit, not a number with 0x.
    EXPECT_EQ(parse_number("F", 16, Prefix::none), 15u);
    EXPECT_EQ(parse_number("0x1", 16, Prefix::none), std::nullopt);
    EXPECT_EQ(parse_number("0x1", 16, Prefix::optional), 1u);
}

}  // namespace
}  // namespace fins::hex
