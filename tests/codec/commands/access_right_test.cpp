// 0C 01 .. 0C 03 access right commands (W342 5-3-24 .. 5-3-26, frames 6/0C01).
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/access_right.hpp"

namespace fins {
namespace {

using test::encode;
using test::hex;
using test::prefix;

template <class C>
void round_trip(const char* name) {
    SCOPED_TRACE(name);
    const C c{};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("FFFF"));  // "Always FFFF (hex)"
    auto d = C::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->program_number, any_program);
    for (std::size_t n = 0; n < params.size(); ++n)
        EXPECT_EQ(C::decode(prefix(params, n)).error(), EndCode::command_too_short);
    EXPECT_EQ(C::decode(hex("FFFF00")).error(), EndCode::command_too_long);
    // Another program number decodes: the handler answers 1106 for it.
    auto other = C::decode(hex("0001"));
    ASSERT_TRUE(other);
    EXPECT_EQ(other->program_number, 0x0001);
    EXPECT_TRUE(c.decode_response({}));
    EXPECT_EQ(c.decode_response(hex("00")).error(), ClientError::malformed_response);
}

TEST(AccessRight, W342_5_3_24_to_26_RoundTrips) {
    round_trip<AccessRightAcquire>("0C01");
    round_trip<AccessRightForcedAcquire>("0C02");
    round_trip<AccessRightRelease>("0C03");
}

TEST(AccessRightHolder, W342_5_3_24_HolderIsUnitNodeNetwork) {
    const AccessRightHolder h{NodeAddress{0x01, 0x14, 0x10}};
    const auto data = encode(h);
    EXPECT_EQ(data, hex("10 14 01"));  // unit, node, network (frames 6/0C01)
    auto d = AccessRightHolder::decode(data);
    ASSERT_TRUE(d);
    EXPECT_EQ(*d, h);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_FALSE(AccessRightHolder::decode(prefix(data, n)));
    EXPECT_FALSE(AccessRightHolder::decode(hex("10140100")));
}

}  // namespace
}  // namespace fins
