// 28 03 / 28 04 / 28 05 Serial Gateway bodies (W342 5-3-46 .. 5-3-48): encode, decode,
// compare; shorter prefixes fail; the response shapes; broadcast detection.
#include <gtest/gtest.h>

#include <string_view>

#include "codec/test_support.hpp"
#include "fins/commands/serial_gateway.hpp"

namespace fins {
namespace {

using test::encode;
using test::hex;

std::vector<std::uint8_t> ascii(std::string_view s) {
    return {s.begin(), s.end()};
}

TEST(ConvertToCompowayF, W342_5_3_46_RoundTripsNodeSubAddressSidCommandText) {
    // Node 01, sub-address 00, SID 0, 01 01 read variable area C0 0000 00 0001.
    const auto params = ascii(
        "01000"
        "0101"
        "C00000000001");
    const auto decoded = ConvertToCompowayF::decode(params);
    ASSERT_TRUE(decoded);
    EXPECT_EQ(decoded->command.node, (std::array<std::uint8_t, 2>{'0', '1'}));
    EXPECT_EQ(decoded->command.service_id, '0');
    EXPECT_EQ(decoded->command.command, (std::array<std::uint8_t, 4>{'0', '1', '0', '1'}));
    EXPECT_EQ(std::string_view(reinterpret_cast<const char*>(decoded->command.text.data()),
                               decoded->command.text.size()),
              "C00000000001");
    EXPECT_EQ(encode(*decoded), params);
    EXPECT_FALSE(decoded->broadcast());
    test::expect_shorter_prefixes_fail<ConvertToCompowayF>(
        ascii("01000"
              "0101"));
    EXPECT_TRUE(ConvertToCompowayF::decode(ascii("XX000"
                                                 "3005"
                                                 "0100"))
                    ->broadcast());
}

TEST(ConvertToCompowayF, ResponseShapes) {
    const ConvertToCompowayF request{};
    // Normal: node, sub, end code, MRC SRC, MRES SRES, text.
    EXPECT_TRUE(
        request.decode_response(ascii("0100"
                                      "00"
                                      "0101"
                                      "0000"
                                      "00000064")));
    // Frame error: node, sub, end code only.
    EXPECT_TRUE(
        request.decode_response(ascii("0100"
                                      "13")));
    // Broadcast: nothing.
    EXPECT_TRUE(request.decode_response({}));
    EXPECT_FALSE(
        request.decode_response(ascii("0100"
                                      "00"
                                      "0101")));
}

TEST(ConvertToModbusRtu, W342_5_3_47_RoundTripsAddressFunctionData) {
    const auto params = hex("01 03 00 00 00 02");
    const auto decoded = ConvertToModbusRtu::decode(params);
    ASSERT_TRUE(decoded);
    EXPECT_EQ(decoded->slave, 1);
    EXPECT_EQ(decoded->function, 3);
    EXPECT_EQ(decoded->data.size(), 4U);
    EXPECT_EQ(encode(*decoded), params);
    test::expect_shorter_prefixes_fail<ConvertToModbusRtu>(hex("01 03"));
    std::vector<std::uint8_t> too_long(ConvertToModbusRtu::max_pdu + 1, 0x01);
    EXPECT_EQ(ConvertToModbusRtu::decode(too_long).error(), EndCode::command_too_long);
    EXPECT_TRUE(ConvertToModbusRtu::decode(hex("00 06 00 01 00 05"))->broadcast());
    // Exception response: function with bit 7 set, one exception code.
    EXPECT_TRUE(decoded->decode_response(hex("01 83 02")));
    EXPECT_FALSE(decoded->decode_response(hex("01")));
}

TEST(ConvertToModbusAscii, W342_5_3_48_RoundTripsHexDigits) {
    const auto params = ascii("010300000002");
    const auto decoded = ConvertToModbusAscii::decode(params);
    ASSERT_TRUE(decoded);
    EXPECT_EQ(encode(*decoded), params);
    EXPECT_FALSE(decoded->broadcast());
    test::expect_shorter_prefixes_fail<ConvertToModbusAscii>(ascii("0103"));
    EXPECT_TRUE(ConvertToModbusAscii::decode(ascii("00060001"))->broadcast());
    EXPECT_TRUE(decoded->decode_response(ascii("0103040001000A")));
    EXPECT_FALSE(decoded->decode_response(ascii("01")));
}

// W342 5-3-48 is silent on data the gateway cannot frame: without an even number of hex
// digits there is no LRC to compute, so the port refuses it as a parameter error (110C).
TEST(ConvertToModbusAscii, W342_5_3_48_NonHexOrOddDigitsAre110C) {
    EXPECT_EQ(ConvertToModbusAscii::decode(ascii("01030G00")).error(), EndCode::parameter_error);
    EXPECT_EQ(ConvertToModbusAscii::decode(ascii("0103000")).error(), EndCode::parameter_error);
    std::vector<std::uint8_t> too_long(ConvertToModbusAscii::max_ascii + 2, '0');
    EXPECT_EQ(ConvertToModbusAscii::decode(too_long).error(), EndCode::command_too_long);
}

}  // namespace
}  // namespace fins
