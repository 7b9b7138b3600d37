// Commands 02 01 .. 02 03 (W342 5-3-7 .. 5-3-9, frames 6) and the parameter area
// table: encode -> decode -> compare, every shorter prefix fails with 1002, longer
// fails with 1001 where the length is fixed, client-side response decoding refuses
// wrong lengths and echoes. W342 gives no byte examples for 02 xx (its diagrams were
// lost, frames 6 reconstructs them), so the vectors are built from those layouts.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/parameter_area.hpp"

namespace fins {
namespace {

using test::encode;
using test::expect_longer_fails;
using test::expect_shorter_prefixes_fail;
using test::hex;
using test::prefix;

TEST(ParameterAreaTable, W342_5_3_7_AreasSizesAndTheLayoutOf8000) {
    const auto areas = parameter_area_table();
    ASSERT_EQ(areas.size(), 5u);
    for (std::size_t i = 1; i < areas.size(); ++i)
        EXPECT_LT(areas[i - 1].code, areas[i].code);
    struct Expected {
        std::uint16_t code, words, offset;
        bool whole;
    };
    const Expected expected[] = {{0x8000, 8000, 0x0000, true},
                                 {0x8002, 5184, 0x0B00, true},
                                 {0x8010, 512, 0x0000, true},
                                 {0x8012, 1280, 0x0400, true},
                                 {0x8013, 512, 0x0900, false}};
    for (const auto& e : expected) {
        const auto* a = find_parameter_area(e.code);
        ASSERT_NE(a, nullptr) << std::hex << e.code;
        EXPECT_EQ(a->words, e.words);
        EXPECT_EQ(a->offset, e.offset);
        EXPECT_EQ(a->whole_area, e.whole);
    }
    // The four areas and the 512-word reserved block (CV 8011) fill 0000-1F3F exactly.
    EXPECT_EQ(512 + 512 + 1280 + 512 + 5184, 8000);
    EXPECT_EQ(0x0B00 + 5184, 0x1F40);
    EXPECT_EQ(find_parameter_area(std::uint16_t{0x8011}), nullptr);
    EXPECT_EQ(find_parameter_area(std::uint16_t{0x0010}), nullptr);
}

TEST(ParameterAreaTable, FindsByNameAndHexCode) {
    EXPECT_EQ(find_parameter_area("plc-setup")->code, 0x8010);
    EXPECT_EQ(find_parameter_area("io-table")->code, 0x8012);
    EXPECT_EQ(find_parameter_area("routing")->code, 0x8013);
    EXPECT_EQ(find_parameter_area("cpu-bus")->code, 0x8002);
    EXPECT_EQ(find_parameter_area("all")->code, 0x8000);
    EXPECT_EQ(find_parameter_area("8010")->code, 0x8010);
    EXPECT_EQ(find_parameter_area("0x8012")->code, 0x8012);
    EXPECT_EQ(find_parameter_area("8011"), nullptr);
    EXPECT_EQ(find_parameter_area("801"), nullptr);
    EXPECT_EQ(find_parameter_area("x8010"), nullptr);
    EXPECT_EQ(find_parameter_area(""), nullptr);
}

TEST(ParameterAreaRead, RoundTrip) {
    const ParameterAreaRead c{0x8010, 0x0000, 498, false};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8010 0000 01F2"));
    auto d = ParameterAreaRead::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->area, 0x8010);
    EXPECT_EQ(d->start, 0);
    EXPECT_EQ(d->count, 498);
    EXPECT_FALSE(d->last_word);
    expect_shorter_prefixes_fail<ParameterAreaRead>(params);
    expect_longer_fails<ParameterAreaRead>(params);
}

TEST(ParameterAreaRead, Bit15IsKeptApartFromTheCount) {
    auto d = ParameterAreaRead::decode(hex("8013 01FE 8002"));
    ASSERT_TRUE(d);
    EXPECT_EQ(d->count, 2);
    EXPECT_TRUE(d->last_word);
    EXPECT_EQ(encode(*d), hex("8013 01FE 8002"));
}

TEST(ParameterAreaRead, ResponseEchoesAndLengths) {
    const ParameterAreaRead c{0x8013, 0x01FE, 2, false};
    const auto data = hex("8013 01FE 8002 1234 5678");
    auto r = c.decode_response(data);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->area, 0x8013);
    EXPECT_EQ(r->start, 0x01FE);
    EXPECT_EQ(r->count, 2);
    EXPECT_TRUE(r->last_word);
    EXPECT_EQ(r->words, (std::vector<std::uint16_t>{0x1234, 0x5678}));
    EXPECT_EQ(encode(*r), data);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_EQ(c.decode_response(prefix(data, n)).error(), ClientError::malformed_response) << n;
    auto longer = data;
    longer.push_back(0);
    EXPECT_EQ(c.decode_response(longer).error(), ClientError::malformed_response);
    // Wrong echo, more words than asked, count and data disagreeing.
    EXPECT_FALSE(c.decode_response(hex("8010 01FE 8002 1234 5678")));
    EXPECT_FALSE(c.decode_response(hex("8013 01FD 8002 1234 5678")));
    EXPECT_FALSE(c.decode_response(hex("8013 01FE 8003 1234 5678 9ABC")));
    EXPECT_FALSE(c.decode_response(hex("8013 01FE 8001 1234 5678")));
    // Zero words: the fixed part alone.
    EXPECT_TRUE((ParameterAreaRead{0x8010, 0, 0, false}.decode_response(hex("8010 0000 0000"))));
}

TEST(ParameterAreaWrite, RoundTripWithTheLastWordFlag) {
    const auto data = hex("0001 0002");
    const ParameterAreaWrite c{0x8013, 0x01FE, 2, true, data};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8013 01FE 8002 0001 0002"));
    auto d = ParameterAreaWrite::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->area, 0x8013);
    EXPECT_EQ(d->start, 0x01FE);
    EXPECT_EQ(d->count, 2);
    EXPECT_TRUE(d->last_word);
    EXPECT_EQ(std::vector<std::uint8_t>(d->data.begin(), d->data.end()), data);
    // The data length is the handler's to check (1003 after the range checks), so only
    // the 6-byte fixed part is walked.
    expect_shorter_prefixes_fail<ParameterAreaWrite>(hex("8013 01FE 8002"));
    auto no_data = ParameterAreaWrite::decode(hex("8010 0000 0000"));
    ASSERT_TRUE(no_data);
    EXPECT_TRUE(no_data->data.empty());
}

TEST(ParameterAreaWrite, ResponseIsTheEndCodeAlone) {
    const ParameterAreaWrite c{0x8010, 0, 0, false, {}};
    EXPECT_TRUE(c.decode_response({}));
    EXPECT_EQ(c.decode_response(hex("00")).error(), ClientError::malformed_response);
}

TEST(ParameterAreaClear, RoundTrip) {
    const ParameterAreaClear c{0x8012, 0x0000, 1280, false, 0x0000};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8012 0000 0500 0000"));
    auto d = ParameterAreaClear::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->area, 0x8012);
    EXPECT_EQ(d->start, 0);
    EXPECT_EQ(d->count, 1280);
    EXPECT_FALSE(d->last_word);
    EXPECT_EQ(d->value, 0);
    expect_shorter_prefixes_fail<ParameterAreaClear>(params);
    expect_longer_fails<ParameterAreaClear>(params);
    EXPECT_TRUE(c.decode_response({}));
    EXPECT_FALSE(c.decode_response(hex("0000")));
}

}  // namespace
}  // namespace fins
