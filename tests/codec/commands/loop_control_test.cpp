// 02 40 READ MULTIPLE ITEMS FROM FUNCTION BLOCK (seed 001, frames 8): encode -> decode
// -> compare, the board's own length codes (1001 over 2,002 command bytes, 1002 under
// 6, 1003 count mismatch) and client-side response decoding.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/loop_control.hpp"

namespace fins {
namespace {

using test::encode;
using test::hex;
using test::prefix;

TEST(FunctionBlockItemRead, RoundTrip) {
    const FunctionBlockItemRead c{0x0001, {0x0006, 0x0007, 0x0008}};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("0001 0003 0006 0007 0008"));
    auto d = FunctionBlockItemRead::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->block, 1);
    EXPECT_EQ(d->items, c.items);
}

TEST(FunctionBlockItemRead, Seed001_1002UnderSixCommandBytes) {
    // Six bytes counted from MRC: code (2), block (2), number of ITEMs (2).
    const auto params = hex("0001 0001 0006");
    for (std::size_t n = 0; n < 4; ++n) {
        auto r = FunctionBlockItemRead::decode(prefix(params, n));
        ASSERT_FALSE(r) << n;
        EXPECT_EQ(r.error(), EndCode::command_too_short) << n;
    }
    // The fixed part alone is long enough; its count then decides (0 ITEMs decodes,
    // the handler answers 110C; 1 ITEM without its address is 1003).
    EXPECT_TRUE(FunctionBlockItemRead::decode(hex("0001 0000")));
    EXPECT_EQ(FunctionBlockItemRead::decode(prefix(params, 4)).error(),
              EndCode::elements_data_mismatch);
    EXPECT_EQ(FunctionBlockItemRead::decode(prefix(params, 5)).error(),
              EndCode::elements_data_mismatch);
}

TEST(FunctionBlockItemRead, Seed001_1003AddressCountDiffersFromItemCount) {
    EXPECT_EQ(FunctionBlockItemRead::decode(hex("0001 0002 0006")).error(),
              EndCode::elements_data_mismatch);
    EXPECT_EQ(FunctionBlockItemRead::decode(hex("0001 0001 0006 0007")).error(),
              EndCode::elements_data_mismatch);
    EXPECT_EQ(FunctionBlockItemRead::decode(hex("0001 0000 0006")).error(),
              EndCode::elements_data_mismatch);
}

TEST(FunctionBlockItemRead, Seed001_1001OverTwoThousandAndTwoCommandBytes) {
    // 2,002 bytes with the code: 4 + 2 x 998 = 2,000 parameter bytes decode.
    FunctionBlockItemRead c{0, std::vector<std::uint16_t>(998, 0x0004)};
    auto params = encode(c);
    ASSERT_EQ(params.size(), 2000u);
    EXPECT_TRUE(FunctionBlockItemRead::decode(params));
    c.items.push_back(0x0004);
    params = encode(c);
    EXPECT_EQ(FunctionBlockItemRead::decode(params).error(), EndCode::command_too_long);
}

TEST(FunctionBlockItemRead, ResponseItemsInRequestOrder) {
    const FunctionBlockItemRead c{1, {0x0006, 0x0099, 0x0014, 0x001E}};
    // ITEM 099 left out (not in the block): three read normally.
    const auto data = hex("0003 0006 02 0FA0 0014 01 00 001E 04 00000E10");
    auto r = c.decode_response(data);
    ASSERT_TRUE(r);
    ASSERT_EQ(r->items.size(), 3u);
    EXPECT_EQ(r->items[0].item, 6);
    EXPECT_EQ(r->items[0].data, hex("0FA0"));
    EXPECT_EQ(r->items[1].item, 0x14);
    EXPECT_EQ(r->items[1].data, hex("00"));
    EXPECT_EQ(r->items[2].item, 0x1E);
    EXPECT_EQ(r->items[2].data, hex("00000E10"));
    EXPECT_EQ(encode(*r), data);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_EQ(c.decode_response(prefix(data, n)).error(), ClientError::malformed_response) << n;
    auto longer = data;
    longer.push_back(0);
    EXPECT_FALSE(c.decode_response(longer));
    // Out of order, not requested, more ITEMs than requested.
    EXPECT_FALSE(c.decode_response(hex("0002 0014 01 00 0006 02 0FA0")));
    EXPECT_FALSE(c.decode_response(hex("0001 0007 02 0FA0")));
    EXPECT_FALSE(c.decode_response(hex("0005 0006 02 0FA0")));
}

}  // namespace
}  // namespace fins
