// Commands 03 06 .. 03 08 (W342 5-3-10 .. 5-3-12, frames 6): encode -> decode ->
// compare, every shorter prefix fails with 1002, longer fails with 1001 where the
// length is fixed, client-side response decoding refuses wrong lengths and echoes.
// W342 gives no byte examples here; the vectors follow the frames 6 layouts.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/program_area.hpp"

namespace fins {
namespace {

using test::encode;
using test::expect_longer_fails;
using test::expect_shorter_prefixes_fail;
using test::hex;
using test::prefix;

TEST(ProgramAreaRead, RoundTrip) {
    const ProgramAreaRead c{0xFFFF, 0x000003E0, 992, false};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("FFFF 000003E0 03E0"));
    auto d = ProgramAreaRead::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->program_number, 0xFFFF);
    EXPECT_EQ(d->address, 0x3E0u);
    EXPECT_EQ(d->count, 992);
    EXPECT_FALSE(d->last);
    expect_shorter_prefixes_fail<ProgramAreaRead>(params);
    expect_longer_fails<ProgramAreaRead>(params);
    auto flagged = ProgramAreaRead::decode(hex("FFFF 00000000 8004"));
    ASSERT_TRUE(flagged);
    EXPECT_EQ(flagged->count, 4);
    EXPECT_TRUE(flagged->last);
}

TEST(ProgramAreaRead, ResponseEchoesAndLengths) {
    const ProgramAreaRead c{0xFFFF, 0x00031FF8, 992, false};
    // Cut at the end of the area: 8 bytes, bit 15 on.
    const auto data = hex("FFFF 00031FF8 8008 0102030405060708");
    auto r = c.decode_response(data);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->program_number, 0xFFFF);
    EXPECT_EQ(r->address, 0x31FF8u);
    EXPECT_EQ(r->count, 8);
    EXPECT_TRUE(r->last);
    EXPECT_EQ(r->data, hex("0102030405060708"));
    EXPECT_EQ(encode(*r), data);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_EQ(c.decode_response(prefix(data, n)).error(), ClientError::malformed_response) << n;
    auto longer = data;
    longer.push_back(0);
    EXPECT_FALSE(c.decode_response(longer));
    EXPECT_FALSE(c.decode_response(hex("0000 00031FF8 8008 0102030405060708")));
    EXPECT_FALSE(c.decode_response(hex("FFFF 00031FFC 8008 0102030405060708")));
    const ProgramAreaRead small{0xFFFF, 0, 4, false};
    EXPECT_FALSE(small.decode_response(hex("FFFF 00000000 0008 0102030405060708")));
}

TEST(ProgramAreaWrite, RoundTrip) {
    const auto data = hex("11223344 55667788");
    const ProgramAreaWrite c{0xFFFF, 0x00000008, 8, true, data};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("FFFF 00000008 8008 11223344 55667788"));
    auto d = ProgramAreaWrite::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->program_number, 0xFFFF);
    EXPECT_EQ(d->address, 8u);
    EXPECT_EQ(d->count, 8);
    EXPECT_TRUE(d->last);
    EXPECT_EQ(std::vector<std::uint8_t>(d->data.begin(), d->data.end()), data);
    expect_shorter_prefixes_fail<ProgramAreaWrite>(hex("FFFF 00000008 8008"));
}

TEST(ProgramAreaWrite, W342_5_3_11_ResponseEchoesProgramNumberAddressAndCount) {
    const ProgramAreaWrite c{0xFFFF, 0x00000008, 8, true, {}};
    const auto echo = hex("FFFF 00000008 8008");
    auto r = c.decode_response(echo);
    ASSERT_TRUE(r);
    EXPECT_EQ(*r, (ProgramAreaWriteResponse{0xFFFF, 8, 8, true}));
    EXPECT_EQ(encode(*r), echo);
    for (std::size_t n = 0; n < echo.size(); ++n)
        EXPECT_FALSE(c.decode_response(prefix(echo, n))) << n;
    EXPECT_FALSE(c.decode_response(hex("FFFF 00000008 8008 00")));
    EXPECT_FALSE(c.decode_response(hex("FFFF 0000000C 8008")));
    EXPECT_FALSE(c.decode_response(hex("FFFF 00000008 800C")));
    // Bit 15 in the echo is not compared: it says nothing about the data.
    EXPECT_TRUE(c.decode_response(hex("FFFF 00000008 0008")));
}

TEST(ProgramAreaClear, RoundTrip) {
    for (std::uint8_t code : {clear_without_interrupt_tasks, clear_with_interrupt_tasks}) {
        const ProgramAreaClear c{0xFFFF, code};
        const auto params = encode(c);
        EXPECT_EQ(params, (std::vector<std::uint8_t>{0xFF, 0xFF, code}));
        auto d = ProgramAreaClear::decode(params);
        ASSERT_TRUE(d);
        EXPECT_EQ(d->program_number, 0xFFFF);
        EXPECT_EQ(d->clear_code, code);
        expect_shorter_prefixes_fail<ProgramAreaClear>(params);
        expect_longer_fails<ProgramAreaClear>(params);
        EXPECT_TRUE(c.decode_response({}));
        EXPECT_FALSE(c.decode_response(hex("00")));
    }
}

}  // namespace
}  // namespace fins
