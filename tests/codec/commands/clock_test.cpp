// CLOCK READ 07 01 and CLOCK WRITE 07 02 (W342 5-3-19, 5-3-20; frames 5.3): BCD
// fields, the 5/6/7-byte write variants, the year rule, bad lengths and non-BCD bytes.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/clock.hpp"

namespace fins {
namespace {

using test::encode;
using test::hex;
using test::prefix;

TEST(Bcd, ConvertsBothWays) {
    EXPECT_EQ(to_bcd(0), 0x00);
    EXPECT_EQ(to_bcd(59), 0x59);
    EXPECT_EQ(to_bcd(99), 0x99);
    EXPECT_EQ(from_bcd(0x23), 23);
    EXPECT_FALSE(from_bcd(0x1A));
    EXPECT_FALSE(from_bcd(0xA1));
    for (unsigned v = 0; v <= 99; ++v)
        EXPECT_EQ(from_bcd(to_bcd(static_cast<std::uint8_t>(v))), v);
}

TEST(Clock, W342_5_3_19_YearRule98And99Are1998And1999) {
    EXPECT_EQ(full_year(98), 1998);
    EXPECT_EQ(full_year(99), 1999);
    EXPECT_EQ(full_year(0), 2000);
    EXPECT_EQ(full_year(96), 2096);
    EXPECT_EQ(full_year(97), 2097);
}

TEST(ClockRead, NoParametersAndSevenByteAnswer) {
    EXPECT_TRUE(encode(ClockRead{}).empty());
    EXPECT_TRUE(ClockRead::decode({}));
    EXPECT_EQ(ClockRead::decode(hex("00")).error(), EndCode::command_too_long);

    // 2024-02-29 23:59:58, Thursday.
    const auto data = hex("24 02 29 23 59 58 04");
    const auto r = ClockRead{}.decode_response(data);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->time, (ClockTime{24, 2, 29, 23, 59, 58, 4}));
    EXPECT_EQ(encode(*r), data);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_EQ(ClockRead{}.decode_response(prefix(data, n)).error(),
                  ClientError::malformed_response);
    EXPECT_EQ(ClockRead{}.decode_response(hex("24 02 29 23 59 58 04 00")).error(),
              ClientError::malformed_response);
    EXPECT_EQ(ClockRead{}.decode_response(hex("24 0A 29 23 59 58 04")).error(),
              ClientError::malformed_response);
}

TEST(ClockWrite, W342_5_3_20_FiveSixAndSevenByteVariants) {
    ClockWrite c{24, 12, 31, 23, 59, std::nullopt, std::nullopt};
    EXPECT_EQ(encode(c), hex("24 12 31 23 59"));
    c.second = 30;
    EXPECT_EQ(encode(c), hex("24 12 31 23 59 30"));
    c.day_of_week = 2;
    const auto seven = encode(c);
    EXPECT_EQ(seven, hex("24 12 31 23 59 30 02"));
    // A day of week without a second goes out with second 00.
    EXPECT_EQ(encode(ClockWrite{24, 1, 1, 0, 0, std::nullopt, 1}), hex("24 01 01 00 00 00 01"));

    const auto d = ClockWrite::decode(seven);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->year, 24);
    EXPECT_EQ(d->month, 12);
    EXPECT_EQ(d->day, 31);
    EXPECT_EQ(d->hour, 23);
    EXPECT_EQ(d->minute, 59);
    EXPECT_EQ(d->second, 30);
    EXPECT_EQ(d->day_of_week, 2);
    const auto six = ClockWrite::decode(prefix(seven, 6));
    ASSERT_TRUE(six);
    EXPECT_EQ(six->second, 30);
    EXPECT_FALSE(six->day_of_week);
    const auto five = ClockWrite::decode(prefix(seven, 5));
    ASSERT_TRUE(five);
    EXPECT_FALSE(five->second);
    EXPECT_FALSE(five->day_of_week);
    for (std::size_t n = 0; n < 5; ++n)
        EXPECT_EQ(ClockWrite::decode(prefix(seven, n)).error(), EndCode::command_too_short);
    auto longer = seven;
    longer.push_back(0);
    EXPECT_EQ(ClockWrite::decode(longer).error(), EndCode::command_too_long);
    EXPECT_TRUE(c.decode_response({}));
    EXPECT_EQ(c.decode_response(hex("00")).error(), ClientError::malformed_response);
}

TEST(ClockWrite, W342_5_3_20_NonBcdFieldIs110C) {
    EXPECT_EQ(ClockWrite::decode(hex("2A 01 01 00 00")).error(), EndCode::parameter_error);
    EXPECT_EQ(ClockWrite::decode(hex("24 01 01 00 00 5F")).error(), EndCode::parameter_error);
    // Out-of-range BCD (month 13) decodes; the CPU Unit model refuses it.
    EXPECT_TRUE(ClockWrite::decode(hex("24 13 01 00 00")));
    // The day of week is not BCD-checked here (07 is out of range, for the model).
    EXPECT_EQ(ClockWrite::decode(hex("24 01 01 00 00 00 07"))->day_of_week, 7);
}

TEST(ClockWrite, ValuesAbove99CannotBeSentAsBcd) {
    EXPECT_EQ(encode(ClockWrite{100, 1, 1, 0, 0, std::nullopt, std::nullopt}),
              hex("FF 01 01 00 00"));
}

}  // namespace
}  // namespace fins
