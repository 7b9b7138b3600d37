// CYCLE TIME READ 06 20 (W342 5-3-18): both operations round trip; the manual's
// example value decodes; bad lengths and parameters fail.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/status.hpp"

namespace fins {
namespace {

using test::encode;
using test::hex;
using test::prefix;

TEST(CycleTimeRead, RoundTripBothOperations) {
    for (auto op : {CycleTimeOperation::initialize, CycleTimeOperation::read}) {
        const CycleTimeRead c{op};
        const auto params = encode(c);
        EXPECT_EQ(params, std::vector<std::uint8_t>{static_cast<std::uint8_t>(op)});
        const auto d = CycleTimeRead::decode(params);
        ASSERT_TRUE(d);
        EXPECT_EQ(d->operation, op);
        EXPECT_EQ(CycleTimeRead::decode(prefix(params, 0)).error(), EndCode::command_too_short);
        EXPECT_EQ(CycleTimeRead::decode(hex("01 00")).error(), EndCode::command_too_long);
    }
}

TEST(CycleTimeRead, W342_5_3_18_ParameterOtherThan00Or01Is110C) {
    for (int v : {0x02, 0x10, 0xFF})
        EXPECT_EQ(
            CycleTimeRead::decode(std::vector<std::uint8_t>{static_cast<std::uint8_t>(v)}).error(),
            EndCode::parameter_error);
}

TEST(CycleTimeRead, W342_5_3_18_ExampleAverage65ms) {
    // The manual's example: 00 00 02 8A is 650 x 0.1 ms = 65.0 ms.
    const auto data = hex("0000028A 000002BC 00000258");
    const CycleTimeRead read{CycleTimeOperation::read};
    const auto r = read.decode_response(data);
    ASSERT_TRUE(r);
    ASSERT_TRUE(r->times);
    EXPECT_EQ(r->times->average, 650U);
    EXPECT_EQ(r->times->maximum, 700U);
    EXPECT_EQ(r->times->minimum, 600U);
    EXPECT_EQ(encode(*r), data);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_EQ(read.decode_response(prefix(data, n)).error(), ClientError::malformed_response);
    auto longer = data;
    longer.push_back(0);
    EXPECT_EQ(read.decode_response(longer).error(), ClientError::malformed_response);
}

TEST(CycleTimeRead, InitializeAnswersTheEndCodeOnly) {
    const CycleTimeRead init{CycleTimeOperation::initialize};
    const auto r = init.decode_response({});
    ASSERT_TRUE(r);
    EXPECT_FALSE(r->times);
    EXPECT_TRUE(encode(*r).empty());
    EXPECT_EQ(init.decode_response(hex("00")).error(), ClientError::malformed_response);
}

}  // namespace
}  // namespace fins
