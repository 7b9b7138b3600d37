// Commands 01 01 .. 01 05 (W342 5-3-2 .. 5-3-6): encode -> decode -> compare, every
// shorter prefix fails with 1002, longer fails with 1001 where the length is fixed, and
// client-side response decoding refuses wrong lengths.
#include <gtest/gtest.h>

#include "codec/test_support.hpp"
#include "fins/commands/memory_area.hpp"

namespace fins {
namespace {

using test::encode;
using test::expect_longer_fails;
using test::expect_shorter_prefixes_fail;
using test::hex;
using test::prefix;

TEST(MemoryAreaRead, RoundTrip) {
    const MemoryAreaRead c{{0x30, 0x000A, 0x0D}, 3};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("30 00 0A 0D 00 03"));
    auto d = MemoryAreaRead::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->start, c.start);
    EXPECT_EQ(d->count, c.count);
    expect_shorter_prefixes_fail<MemoryAreaRead>(params);
    expect_longer_fails<MemoryAreaRead>(params);
}

TEST(MemoryAreaRead, ResponseLengths) {
    const MemoryAreaRead words{{0x82, 10, 0}, 3};
    const auto data = hex("00 01 00 02 00 03");
    auto r = words.decode_response(data);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->data, data);
    EXPECT_EQ(encode(*r), data);
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_EQ(words.decode_response(prefix(data, n)).error(), ClientError::malformed_response);
    auto longer = data;
    longer.push_back(0);
    EXPECT_EQ(words.decode_response(longer).error(), ClientError::malformed_response);

    // Element sizes follow the area code: 1 byte bits, 4 bytes IR / word with forced status.
    EXPECT_TRUE((MemoryAreaRead{{0x30, 0, 0}, 3}.decode_response(hex("01 00 01"))));
    EXPECT_TRUE((MemoryAreaRead{{0xDC, 0x100, 0}, 2}.decode_response(hex("0000000100000002"))));
    EXPECT_TRUE((MemoryAreaRead{{0xF0, 0, 0}, 1}.decode_response(hex("00 00 12 34"))));
    // Zero elements: an empty normal response (5-3-2 note 1).
    EXPECT_TRUE((MemoryAreaRead{{0x82, 0, 0}, 0}.decode_response({})));
    // Unknown area code: the length cannot be checked.
    EXPECT_EQ((MemoryAreaRead{{0x03, 0, 0}, 0}.decode_response({})).error(),
              ClientError::malformed_response);
}

TEST(MemoryAreaWrite, RoundTrip) {
    const auto data = hex("12 34 56 78");
    const MemoryAreaWrite c{{0x82, 0x0064, 0}, 2, data};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("82 00 64 00 00 02 12 34 56 78"));
    auto d = MemoryAreaWrite::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->start, c.start);
    EXPECT_EQ(d->count, 2);
    EXPECT_EQ(std::vector<std::uint8_t>(d->data.begin(), d->data.end()), data);
    // Below the fixed part: 1002. From 6 bytes on the decoder accepts and leaves the
    // count/data check to the handler (memory_area.hpp), so only the fixed part is walked.
    expect_shorter_prefixes_fail<MemoryAreaWrite>(hex("82 00 64 00 00 02"));
    for (std::size_t n = 6; n <= params.size(); ++n) {
        auto p = MemoryAreaWrite::decode(prefix(params, n));
        ASSERT_TRUE(p) << n;
        EXPECT_EQ(p->data.size(), n - 6);
    }
    EXPECT_TRUE(c.decode_response({}));
    EXPECT_EQ(c.decode_response(hex("00")).error(), ClientError::malformed_response);
}

TEST(MemoryAreaFill, RoundTrip) {
    const MemoryAreaFill c{{0xB1, 0x0010, 0}, 0x20, 0xBEEF};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("B1 00 10 00 00 20 BE EF"));
    auto d = MemoryAreaFill::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->start, c.start);
    EXPECT_EQ(d->count, c.count);
    EXPECT_EQ(d->value, c.value);
    expect_shorter_prefixes_fail<MemoryAreaFill>(params);
    expect_longer_fails<MemoryAreaFill>(params);
    EXPECT_TRUE(c.decode_response({}));
    EXPECT_EQ(c.decode_response(hex("00 00")).error(), ClientError::malformed_response);
}

TEST(MemoryAreaTransfer, RoundTrip) {
    const MemoryAreaTransfer c{{0x82, 0x0100, 0}, {0xA3, 0x0200, 0}, 50};
    const auto params = encode(c);
    EXPECT_EQ(params, hex("82 01 00 00 A3 02 00 00 00 32"));
    auto d = MemoryAreaTransfer::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->source, c.source);
    EXPECT_EQ(d->destination, c.destination);
    EXPECT_EQ(d->count, c.count);
    expect_shorter_prefixes_fail<MemoryAreaTransfer>(params);
    expect_longer_fails<MemoryAreaTransfer>(params);
    EXPECT_TRUE(c.decode_response({}));
    EXPECT_EQ(c.decode_response(hex("01")).error(), ClientError::malformed_response);
}

MultipleMemoryAreaRead sample_multi() {
    return MultipleMemoryAreaRead{{
        {0x82, 0x000A, 0},  // D10: 2 bytes
        {0x30, 0x0001, 3},  // CIO1.03: 1 byte
        {0xDC, 0x0102, 0},  // IR2: 4 bytes
        {0x70, 0x0000, 1},  // with forced status: 1 byte
    }};
}

TEST(MultipleMemoryAreaRead, RoundTrip) {
    const auto c = sample_multi();
    const auto params = encode(c);
    EXPECT_EQ(params, hex("82 00 0A 00 30 00 01 03 DC 01 02 00 70 00 00 01"));
    auto d = MultipleMemoryAreaRead::decode(params);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->items, c.items);
    // A prefix cut inside an element is short; on an element boundary it is a valid
    // request for fewer elements (5-3-5: even none).
    for (std::size_t n = 0; n < params.size(); ++n) {
        auto r = MultipleMemoryAreaRead::decode(prefix(params, n));
        if (n % 4 == 0) {
            ASSERT_TRUE(r) << n;
            EXPECT_EQ(r->items.size(), n / 4);
        } else {
            ASSERT_FALSE(r) << n;
            EXPECT_EQ(r.error(), EndCode::command_too_short) << n;
        }
    }
}

TEST(MultipleMemoryAreaRead, ElementLimit) {
    MultipleMemoryAreaRead c;
    c.items.assign(max_multiple_read_elements, MemoryAddress{0x82, 1, 0});
    auto params = encode(c);
    EXPECT_TRUE(MultipleMemoryAreaRead::decode(params));
    // 168 elements: too long (5-3-5, Ethernet / Controller Link).
    for (int i = 0; i < 4; ++i)
        params.push_back(0);
    EXPECT_EQ(MultipleMemoryAreaRead::decode(params).error(), EndCode::command_too_long);
    params.resize(params.size() - 3);  // 669 bytes: too long wins over not-a-multiple
    EXPECT_EQ(MultipleMemoryAreaRead::decode(params).error(), EndCode::command_too_long);
}

TEST(MultipleMemoryAreaRead, Response) {
    const auto c = sample_multi();
    const auto data = hex("82 12 34  30 01  DC 00 01 00 02  70 03");
    auto r = c.decode_response(data);
    ASSERT_TRUE(r) << r.error().message();
    const MultipleMemoryAreaReadResponse expected{
        {{0x82, 0x1234}, {0x30, 0x01}, {0xDC, 0x00010002}, {0x70, 0x03}}};
    EXPECT_EQ(*r, expected);
    EXPECT_EQ(encode(expected), data);
    // Every shorter or longer answer is malformed.
    for (std::size_t n = 0; n < data.size(); ++n)
        EXPECT_EQ(c.decode_response(prefix(data, n)).error(), ClientError::malformed_response) << n;
    auto longer = data;
    longer.push_back(0);
    EXPECT_EQ(c.decode_response(longer).error(), ClientError::malformed_response);
    // Item codes must be echoed in request order.
    auto swapped = hex("30 01  82 12 34  DC 00 01 00 02  70 03");
    EXPECT_EQ(c.decode_response(swapped).error(), ClientError::malformed_response);
    // An unknown code cannot be sized.
    const MultipleMemoryAreaRead unknown{{{0x03, 0, 0}}};
    EXPECT_EQ(unknown.decode_response(hex("03 00")).error(), ClientError::malformed_response);
    // No elements: empty normal response.
    EXPECT_TRUE(MultipleMemoryAreaRead{}.decode_response({}));
}

TEST(MemoryAreaCommands, CodesAndNames) {
    EXPECT_EQ(MemoryAreaRead::code.value(), 0x0101);
    EXPECT_EQ(MemoryAreaWrite::code.value(), 0x0102);
    EXPECT_EQ(MemoryAreaFill::code.value(), 0x0103);
    EXPECT_EQ(MultipleMemoryAreaRead::code.value(), 0x0104);
    EXPECT_EQ(MemoryAreaTransfer::code.value(), 0x0105);
    EXPECT_EQ(MemoryAreaTransfer::name, "MEMORY AREA TRANSFER");
}

}  // namespace
}  // namespace fins
