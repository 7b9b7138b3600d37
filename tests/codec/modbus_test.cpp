// Modbus-RTU and Modbus-ASCII framing: CRC-16 and LRC against the Modbus over Serial
// Line specification's examples, RTU response lengths, ASCII parsing.
#include <gtest/gtest.h>

#include <string_view>

#include "codec/test_support.hpp"
#include "fins/modbus.hpp"

namespace fins::modbus {
namespace {

using test::hex;

std::vector<std::uint8_t> ascii(std::string_view s) {
    return {s.begin(), s.end()};
}

TEST(ModbusRtu, Crc16OfTheWellKnownReadHoldingRegistersRequest) {
    // 01 03 00 00 00 0A -> CRC C5 CD (low byte first on the wire).
    EXPECT_EQ(crc16(hex("01 03 00 00 00 0A")), 0xCDC5);
    std::vector<std::uint8_t> out(16);
    ByteWriter w(out);
    write_rtu_frame(w, hex("01 03 00 00 00 0A"));
    out.resize(w.size());
    EXPECT_EQ(out, hex("01 03 00 00 00 0A C5 CD"));
    EXPECT_TRUE(rtu_crc_ok(out));
    out[3] ^= 0x10;
    EXPECT_FALSE(rtu_crc_ok(out));
    EXPECT_FALSE(rtu_crc_ok(hex("01 03 00")));
}

TEST(ModbusRtu, ResponseSizeFromFunctionCode) {
    EXPECT_FALSE(rtu_response_size(hex("01")));
    EXPECT_FALSE(rtu_response_size(hex("01 03")));
    EXPECT_EQ(rtu_response_size(hex("01 03 04")), 3U + 4U + 2U);
    EXPECT_EQ(rtu_response_size(hex("01 06")), 8U);
    EXPECT_EQ(rtu_response_size(hex("01 10")), 8U);
    EXPECT_EQ(rtu_response_size(hex("01 16")), 10U);
    EXPECT_EQ(rtu_response_size(hex("01 83")), 5U);  // exception
    EXPECT_FALSE(rtu_response_size(hex("01 2B")));   // unknown: the silence decides
}

TEST(ModbusAscii, LrcAndFrameOfTheSpecExample) {
    // Modbus over Serial Line 2.5.2.2 style: 01 03 00 00 00 0A -> LRC F2.
    EXPECT_EQ(lrc(hex("01 03 00 00 00 0A")), 0xF2);
    std::vector<std::uint8_t> out(64);
    ByteWriter w(out);
    ASSERT_TRUE(write_ascii_frame(w, ascii("01030000000A")));
    out.resize(w.size());
    EXPECT_EQ(out, ascii(":01030000000AF2\r\n"));

    std::vector<std::uint8_t> none(64);
    ByteWriter w2(none);
    EXPECT_FALSE(write_ascii_frame(w2, ascii("0103Z")));
    EXPECT_EQ(w2.size(), 0U);
}

TEST(ModbusAscii, ParsesSplitNoisyAndBadFrames) {
    const auto f = ascii(":0103040001000AED\r\n");
    for (std::size_t n = 0; n < f.size(); ++n)
        EXPECT_EQ(parse_ascii_frame(Bytes{f.data(), n}).status, AsciiParse::Status::need_more) << n;
    auto noisy = ascii("xx");
    noisy.insert(noisy.end(), f.begin(), f.end());
    const auto parsed = parse_ascii_frame(noisy);
    ASSERT_EQ(parsed.status, AsciiParse::Status::complete);
    EXPECT_EQ(parsed.consumed, noisy.size());
    EXPECT_EQ(
        std::string_view(reinterpret_cast<const char*>(parsed.ascii.data()), parsed.ascii.size()),
        "0103040001000A");
    EXPECT_EQ(parse_ascii_frame(ascii(":0103040001000AEE\r\n")).status,
              AsciiParse::Status::bad_checksum);
    EXPECT_EQ(parse_ascii_frame(ascii(":01030G\r\n")).status, AsciiParse::Status::malformed);
    EXPECT_EQ(parse_ascii_frame(ascii(":0\r\n")).status, AsciiParse::Status::malformed);
}

TEST(ModbusAscii, HexDecodeBounds) {
    std::array<std::uint8_t, 2> out{};
    EXPECT_EQ(hex_decode(ascii("0aFF"), out), 2U);
    EXPECT_EQ(out[0], 0x0A);
    EXPECT_FALSE(hex_decode(ascii("0a0b0c"), out));
    EXPECT_FALSE(hex_decode(ascii("0"), out));
}

}  // namespace
}  // namespace fins::modbus
