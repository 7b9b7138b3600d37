// 06 01 CPU UNIT STATUS READ and the 09 20 family (W342 5-3-17, 5-3-21 .. 5-3-23):
// encode -> decode -> compare, every shorter prefix fails, longer fails, variant bits.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/diagnostics.hpp"

namespace fins {
namespace {

using test::encode;
using test::hex;
using test::prefix;

template <class C>
void expect_prefixes_and_longer_fail(const std::vector<std::uint8_t>& params) {
    for (std::size_t n = 0; n < params.size(); ++n) {
        auto r = C::decode(prefix(params, n));
        ASSERT_FALSE(r) << C::name << " prefix " << n;
        EXPECT_EQ(r.error(), EndCode::command_too_short) << C::name << " prefix " << n;
    }
    auto longer = params;
    longer.push_back(0);
    auto r = C::decode(longer);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error(), EndCode::command_too_long);
}

TEST(CpuUnitStatusRead, W342_5_3_17_NoParameters) {
    EXPECT_TRUE(encode(CpuUnitStatusRead{}).empty());
    EXPECT_TRUE(CpuUnitStatusRead::decode({}));
    EXPECT_EQ(CpuUnitStatusRead::decode(hex("00")).error(), EndCode::command_too_long);
}

TEST(CpuUnitStatusRead, W342_5_3_17_ResponseRoundTripAndLength) {
    CpuUnitStatusReadResponse s;
    s.status = status_running | status_battery_present;
    s.mode = mode_run;
    s.fatal_errors = 0x0040;
    s.non_fatal_errors = 0x8010;
    s.messages = 0x0009;
    s.error_code = 0xC105;
    s.error_message = "MOTOR OVERLOAD  ";
    const auto data = encode(s);
    EXPECT_EQ(data, hex("05 04 0040 8010 0009 C105 4D4F544F52204F5645524C4F41442020"));
    ASSERT_EQ(data.size(), cpu_status_size);
    auto d = CpuUnitStatusRead{}.decode_response(data);
    ASSERT_TRUE(d);
    EXPECT_EQ(*d, s);
    EXPECT_TRUE(d->running());
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_EQ(CpuUnitStatusRead{}.decode_response(prefix(data, n)).error(),
                  ClientError::malformed_response);
    auto longer = data;
    longer.push_back(0);
    EXPECT_FALSE(CpuUnitStatusRead{}.decode_response(longer));
}

TEST(CpuUnitStatusRead, W342_5_3_17_ShortMessageIsPaddedWithSpaces) {
    CpuUnitStatusReadResponse s;
    s.error_message = "AB";
    const auto data = encode(s);
    const std::vector<std::uint8_t> tail(data.end() - 16, data.end());
    EXPECT_EQ(tail, hex("4142 2020202020202020 202020202020"));
}

TEST(MessageRead, W342_5_3_21_RoundTrip) {
    const MessageRead c{0x81};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("0081"));
    auto d = MessageRead::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->messages, 0x81);
    expect_prefixes_and_longer_fail<MessageRead>(params);
}

TEST(MessageRead, W342_5_3_21_OtherVariantsAndStrayBitsAre110C) {
    for (const char* word : {"4001", "8001", "C000", "0100", "2000", "3F01"})
        EXPECT_EQ(MessageRead::decode(hex(word)).error(), EndCode::parameter_error) << word;
}

TEST(MessageRead, W342_5_3_21_ResponseThirtyTwoBytesPerBitAscending) {
    MessageReadResponse r{0x05, {std::string(32, 'A'), std::string("B") + std::string(31, ' ')}};
    const auto data = encode(r);
    ASSERT_EQ(data.size(), 2u + 64u);
    EXPECT_EQ(data[0], 0x00);
    EXPECT_EQ(data[1], 0x05);
    auto d = MessageRead{0x05}.decode_response(data);
    ASSERT_TRUE(d);
    EXPECT_EQ(*d, r);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_FALSE(MessageRead{0x05}.decode_response(prefix(data, n))) << n;
    // No bits requested: the word alone.
    auto none = MessageRead{0}.decode_response(hex("0000"));
    ASSERT_TRUE(none);
    EXPECT_TRUE(none->texts.empty());
    // A word with variant bits is not a read answer.
    EXPECT_FALSE(MessageRead{0}.decode_response(hex("4000")));
}

TEST(MessageClear, W342_5_3_22_RoundTrip) {
    const MessageClear c{0x0C};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("400C"));
    auto d = MessageClear::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->messages, 0x0C);
    expect_prefixes_and_longer_fail<MessageClear>(params);
    EXPECT_EQ(MessageClear::decode(hex("000C")).error(), EndCode::parameter_error);
    EXPECT_EQ(MessageClear::decode(hex("410C")).error(), EndCode::parameter_error);
    EXPECT_TRUE(c.decode_response({}));
    EXPECT_FALSE(c.decode_response(hex("00")));
}

TEST(FalFalsRead, W342_5_3_23_RoundTrip) {
    const FalFalsRead c{0x01FF};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("81FF"));
    auto d = FalFalsRead::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->number, 0x01FF);
    expect_prefixes_and_longer_fail<FalFalsRead>(params);
    EXPECT_EQ(FalFalsRead::decode(hex("C001")).error(), EndCode::parameter_error);
    EXPECT_EQ(FalFalsRead::decode(hex("0001")).error(), EndCode::parameter_error);
}

TEST(FalFalsRead, W342_5_3_23_ResponseEchoesTheWordWithBit15) {
    const FalFalsReadResponse r{5, "LOW PRESSURE    "};
    const auto data = encode(r);
    EXPECT_EQ(data, hex("8005 4C4F57205052455353555245 20202020"));
    auto d = FalFalsRead{5}.decode_response(data);
    ASSERT_TRUE(d);
    EXPECT_EQ(*d, r);
    EXPECT_TRUE(FalFalsRead{5}.decode_response(hex("0005 20202020202020202020202020202020")));
    EXPECT_FALSE(FalFalsRead{6}.decode_response(data));  // another number
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_FALSE(FalFalsRead{5}.decode_response(prefix(data, n))) << n;
}

TEST(MessageCommand, W342_5_3_21_BitsFifteenAndFourteenSelectTheVariant) {
    auto read = MessageCommand::decode(hex("00FF"));
    ASSERT_TRUE(read);
    EXPECT_TRUE(std::holds_alternative<MessageRead>(read->command));
    auto clear = MessageCommand::decode(hex("4001"));
    ASSERT_TRUE(clear);
    EXPECT_TRUE(std::holds_alternative<MessageClear>(clear->command));
    auto fal = MessageCommand::decode(hex("8123"));
    ASSERT_TRUE(fal);
    ASSERT_TRUE(std::holds_alternative<FalFalsRead>(fal->command));
    EXPECT_EQ(std::get<FalFalsRead>(fal->command).number, 0x0123);
    EXPECT_EQ(MessageCommand::decode(hex("C000")).error(), EndCode::parameter_error);
    EXPECT_EQ(MessageCommand::decode(hex("0200")).error(), EndCode::parameter_error);
    EXPECT_EQ(MessageCommand::decode(hex("00")).error(), EndCode::command_too_short);
    EXPECT_EQ(MessageCommand::decode(hex("000000")).error(), EndCode::command_too_long);
}

}  // namespace
}  // namespace fins
