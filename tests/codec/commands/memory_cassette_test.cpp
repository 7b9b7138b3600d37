// 22 20 MEMORY CASSETTE TRANSFER (W342 5-3-43): the layout choices of
// fins/commands/memory_cassette.hpp (the seed has no byte diagram; fins-frames "2220"
// UNCONFIRMED): encode -> decode -> compare, every shorter prefix fails with 1002, one
// byte more with 1001; the response is 2 bytes for parameter 8000, empty otherwise.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/memory_cassette.hpp"

namespace fins {
namespace {

using test::encode;
using test::expect_longer_fails;
using test::expect_shorter_prefixes_fail;
using test::hex;

// Disk 8003, parameter, 2-byte designation (bits 15 .. 00): six bytes.
TEST(MemoryCassetteTransfer, W342_5_3_43_CommandIsDiskParameterDesignationWord) {
    const MemoryCassetteTransfer c{disk_memory_cassette,
                                   static_cast<std::uint16_t>(CassetteOperation::save),
                                   cassette_individual | cassette_dm | cassette_program};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("8003 0000 8041"));
    const auto d = MemoryCassetteTransfer::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->disk, 0x8003);
    EXPECT_EQ(d->operation, 0x0000);
    EXPECT_EQ(d->designation, 0x8041);
    expect_shorter_prefixes_fail<MemoryCassetteTransfer>(params);
    expect_longer_fails<MemoryCassetteTransfer>(params);
}

// The designation word is sent with 0003 and 8000 too (a choice: one fixed layout).
TEST(MemoryCassetteTransfer, W342_5_3_43_DesignationSentWithInitializeAndReadType) {
    for (const auto op : {CassetteOperation::initialize, CassetteOperation::read_type}) {
        const MemoryCassetteTransfer c{disk_memory_cassette, static_cast<std::uint16_t>(op), 0};
        const auto params = encode(c);
        EXPECT_EQ(params.size(), 6U);
        ASSERT_TRUE(MemoryCassetteTransfer::decode(params));
        expect_shorter_prefixes_fail<MemoryCassetteTransfer>(params);
        expect_longer_fails<MemoryCassetteTransfer>(params);
    }
    // Values are the PLC's to judge: an unknown parameter still decodes.
    const auto odd = MemoryCassetteTransfer::decode(hex("8000 0004 7F02"));
    ASSERT_TRUE(odd);
    EXPECT_EQ(odd->operation, 0x0004);
}

// Parameter 8000: the stored data type in 2 bytes; every other parameter: end code only.
TEST(MemoryCassetteTransfer, W342_5_3_43_ReadTypeResponseIsOneWord) {
    const MemoryCassetteTransfer type{disk_memory_cassette,
                                      static_cast<std::uint16_t>(CassetteOperation::read_type), 0};
    const auto r = type.decode_response(hex("0045"));
    ASSERT_TRUE(r);
    EXPECT_EQ(r->stored, cassette_dm | cassette_parameters | cassette_program);
    EXPECT_EQ(test::encode(*r), hex("0045"));
    EXPECT_FALSE(type.decode_response(hex("45")));
    EXPECT_FALSE(type.decode_response(hex("")));
    EXPECT_FALSE(type.decode_response(hex("004500")));

    const MemoryCassetteTransfer save{};
    EXPECT_TRUE(save.decode_response(hex("")));
    EXPECT_FALSE(save.decode_response(hex("0045")));
}

}  // namespace
}  // namespace fins
