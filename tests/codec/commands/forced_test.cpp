// 23 01 FORCED SET/RESET and 23 02 FORCED SET/RESET CANCEL (W342 5-3-44, 5-3-45).
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/forced.hpp"

namespace fins {
namespace {

using test::encode;
using test::hex;
using test::prefix;

TEST(ForcedSetReset, W342_5_3_44_RoundTrip) {
    ForcedSetReset c;
    c.items = {{ForceAction::force_on, {0x30, 0x000A, 0x0D}},
               {ForceAction::release_off, {0x09, 0x8003, 0x00}},
               {ForceAction::release, {0x32, 0x0001, 0x0F}}};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("0003  0001 30000A0D  8000 09800300  FFFF 3200010F"));
    auto d = ForcedSetReset::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->items, c.items);
    // Shorter than the count word: 1002; a count that the items do not match: 1003.
    for (std::size_t n = 0; n < params.size(); ++n) {
        auto r = ForcedSetReset::decode(prefix(params, n));
        ASSERT_FALSE(r) << n;
        EXPECT_EQ(r.error(), n < 2 ? EndCode::command_too_short : EndCode::elements_data_mismatch)
            << n;
    }
    auto longer = params;
    longer.push_back(0);
    EXPECT_EQ(ForcedSetReset::decode(longer).error(), EndCode::elements_data_mismatch);
    EXPECT_TRUE(c.decode_response({}));
    EXPECT_FALSE(c.decode_response(hex("00")));
}

TEST(ForcedSetReset, W342_5_3_44_UnknownDesignationDecodesForTheHandler) {
    auto d = ForcedSetReset::decode(hex("0001 0002 30000000"));
    ASSERT_TRUE(d);
    EXPECT_FALSE(is_force_action(static_cast<std::uint16_t>(d->items[0].action)));
    const std::uint16_t valid[] = {0x0000, 0x0001, 0x8000, 0x8001, 0xFFFF};
    const std::uint16_t invalid[] = {0x0002, 0x8002, 0x7FFF, 0xFFFE, 0x0100};
    for (auto v : valid)
        EXPECT_TRUE(is_force_action(v)) << v;
    for (auto v : invalid)
        EXPECT_FALSE(is_force_action(v)) << v;
}

TEST(ForcedSetReset, W342_5_3_44_ZeroItems) {
    auto d = ForcedSetReset::decode(hex("0000"));
    ASSERT_TRUE(d);
    EXPECT_TRUE(d->items.empty());
    EXPECT_EQ(encode(ForcedSetReset{}), hex("0000"));
}

TEST(ForcedSetResetCancel, W342_5_3_45_NoParameters) {
    EXPECT_TRUE(encode(ForcedSetResetCancel{}).empty());
    EXPECT_TRUE(ForcedSetResetCancel::decode({}));
    EXPECT_EQ(ForcedSetResetCancel::decode(hex("00")).error(), EndCode::command_too_long);
    EXPECT_TRUE(ForcedSetResetCancel{}.decode_response({}));
    EXPECT_FALSE(ForcedSetResetCancel{}.decode_response(hex("00")));
}

}  // namespace
}  // namespace fins
