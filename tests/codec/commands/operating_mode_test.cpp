// RUN 04 01 and STOP 04 02 (W342 5-3-13, 5-3-14): every wire variant encodes, decodes
// and compares; bad lengths, program numbers and mode bytes fail with the manual's codes.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/operating_mode.hpp"

namespace fins {
namespace {

using test::encode;
using test::hex;
using test::prefix;

TEST(Run, RoundTripsEveryVariant) {
    struct Case {
        fins::Run command;
        const char* wire;
        RunMode target;
    };
    const Case cases[] = {
        {fins::Run{}, "", RunMode::monitor},
        {fins::Run{all_programs, std::nullopt}, "FF FF", RunMode::monitor},
        {fins::Run{all_programs, RunMode::monitor}, "FF FF 02", RunMode::monitor},
        {fins::Run{all_programs, RunMode::run}, "FF FF 04", RunMode::run},
    };
    for (const auto& c : cases) {
        const auto params = encode(c.command);
        EXPECT_EQ(params, hex(c.wire)) << c.wire;
        const auto d = fins::Run::decode(params);
        ASSERT_TRUE(d) << c.wire;
        EXPECT_EQ(d->program_number, c.command.program_number);
        EXPECT_EQ(d->mode, c.command.mode);
        EXPECT_EQ(d->target(), c.target);
        EXPECT_TRUE(c.command.decode_response({}));
        EXPECT_EQ(c.command.decode_response(hex("00")).error(), ClientError::malformed_response);
    }
}

TEST(Run, ModeWithoutProgramNumberIsSentWithFFFF) {
    EXPECT_EQ(encode(fins::Run{std::nullopt, RunMode::run}), hex("FF FF 04"));
}

TEST(Run, W342_5_3_13_ShorterPrefixesAreOtherVariantsOrTooShort) {
    const auto params = encode(fins::Run{all_programs, RunMode::run});
    // 0 and 2 bytes are the MONITOR variants; 1 byte is half a program number.
    for (std::size_t n = 0; n < params.size(); ++n) {
        const auto d = fins::Run::decode(prefix(params, n));
        if (n == 1) {
            ASSERT_FALSE(d);
            EXPECT_EQ(d.error(), EndCode::command_too_short);
        } else {
            ASSERT_TRUE(d) << n;
            EXPECT_EQ(d->target(), RunMode::monitor) << n;
        }
    }
    auto longer = params;
    longer.push_back(0);
    EXPECT_EQ(fins::Run::decode(longer).error(), EndCode::command_too_long);
}

TEST(Run, W342_5_3_13_ProgramNumberMustBeFFFF) {
    EXPECT_EQ(fins::Run::decode(hex("00 00")).error(), EndCode::program_missing);
    EXPECT_EQ(fins::Run::decode(hex("00 01 04")).error(), EndCode::program_missing);
    // The program number is checked before the mode byte.
    EXPECT_EQ(fins::Run::decode(hex("FF FE 07")).error(), EndCode::program_missing);
}

TEST(Run, W342_5_3_13_ModeOtherThan02Or04Is110C) {
    for (int mode : {0x00, 0x01, 0x03, 0x05, 0xFF})
        EXPECT_EQ(fins::Run::decode(
                      std::vector<std::uint8_t>{0xFF, 0xFF, static_cast<std::uint8_t>(mode)})
                      .error(),
                  EndCode::parameter_error)
            << mode;
}

TEST(Stop, RoundTripsBothVariants) {
    EXPECT_EQ(encode(Stop{}), hex(""));
    EXPECT_EQ(encode(Stop{all_programs}), hex("FF FF"));
    const auto d = Stop::decode(hex("FF FF"));
    ASSERT_TRUE(d);
    EXPECT_EQ(d->program_number, all_programs);
    const auto bare = Stop::decode({});
    ASSERT_TRUE(bare);
    EXPECT_FALSE(bare->program_number);
    EXPECT_TRUE(Stop{}.decode_response({}));
    EXPECT_EQ(Stop{}.decode_response(hex("00")).error(), ClientError::malformed_response);
}

TEST(Stop, W342_5_3_14_BadLengthsAndProgramNumbers) {
    EXPECT_EQ(Stop::decode(hex("FF")).error(), EndCode::command_too_short);
    EXPECT_EQ(Stop::decode(hex("FF FF 00")).error(), EndCode::command_too_long);
    EXPECT_EQ(Stop::decode(hex("12 34")).error(), EndCode::program_missing);
}

}  // namespace
}  // namespace fins
