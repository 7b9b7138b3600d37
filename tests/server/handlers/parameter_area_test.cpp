// 02 01 .. 02 03 PARAMETER AREA READ/WRITE/CLEAR through full request frames (W342
// 5-3-7 .. 5-3-9): every end code the manual names for them, and the choices where it
// is silent (parameter_areas.hpp), each in a test citing its section.
#include <gtest/gtest.h>

#include <string>

#include <fmt/core.h>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

using plc::OperatingMode;

// `count` words first, first + 1, ... as hex text.
std::string words(std::size_t count, std::uint16_t first = 0) {
    std::string s;
    for (std::size_t i = 0; i < count; ++i)
        s += fmt::format("{:04X}", static_cast<std::uint16_t>(first + i));
    return s;
}

std::string write_cmd(std::uint16_t area, std::uint16_t start, std::size_t count, bool last,
                      std::uint16_t first = 0) {
    return fmt::format("0202 {:04X} {:04X} {:04X} ", area, start, count | (last ? 0x8000u : 0u)) +
           words(count, first);
}

// Writes a whole area in 498-word blocks; returns the first non-zero end code.
std::uint16_t write_whole(Harness& h, std::uint16_t area, std::uint16_t size,
                          std::uint16_t first = 0) {
    for (std::uint16_t at = 0; at < size; at = static_cast<std::uint16_t>(at + 498)) {
        const auto n = std::min<std::uint16_t>(498, static_cast<std::uint16_t>(size - at));
        const auto code =
            h.send(write_cmd(area, at, n, at + n == size, static_cast<std::uint16_t>(first + at)))
                .end_code();
        if (code != 0) return code;
    }
    return 0;
}

TEST(ParameterAreaRead, W342_5_3_7_ReadsAndEchoesAreaStartAndCount) {
    Harness h;
    h.plc.parameters().words(0x8010)[1] = 0x1234;
    const auto r = h.send("0201 8010 0001 0002");
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), to_hex(hex("8010 0001 0002 1234 0000")));
}

TEST(ParameterAreaRead, W342_5_3_7_Bit15MarksTheAreasLastWord) {
    Harness h;
    h.plc.parameters().words(0x8010)[511] = 0xBEEF;
    EXPECT_EQ(h.send("0201 8010 01FF 0001").data_hex(), to_hex(hex("8010 01FF 8001 BEEF")));
    EXPECT_EQ(h.send("0201 8010 01FE 0001").data_hex(), to_hex(hex("8010 01FE 0001 0000")));
    // The last word of the whole range (8000: 1F3F) is the CPU Bus Unit setup's last.
    h.plc.parameters().words(0x8002)[0x143F] = 0x0102;
    EXPECT_EQ(h.send("0201 8000 1F3F 0001").data_hex(), to_hex(hex("8000 1F3F 8001 0102")));
}

TEST(ParameterAreaRead, W342_5_3_7_PastTheEndSendsTheWordsToTheEndWith1104) {
    Harness h;
    h.plc.parameters().words(0x8013)[0x1FF] = 0x00AA;
    const auto r = h.send("0201 8013 01FE 0010");
    EXPECT_EQ(r.end_code(), 0x1104);
    EXPECT_EQ(r.data_hex(), to_hex(hex("8013 01FE 8002 0000 00AA")));
}

TEST(ParameterAreaRead, W342_5_3_7_Over498WordsReads498With110B) {
    // The seed says "1108", which 5-1-3 does not list; 110B is "response too long".
    Harness h;
    const auto r = h.send("0201 8002 0000 01F3");  // 499 words
    EXPECT_EQ(r.end_code(), 0x110B);
    ASSERT_EQ(r.data().size(), 6u + 2u * 498u);
    EXPECT_EQ(to_hex(Bytes(r.data().data(), 6)), to_hex(hex("8002 0000 01F2")));
    // Past the end as well: the end wins (fewer than 498 words, 1104).
    EXPECT_EQ(h.send("0201 8010 0100 01F4").end_code(), 0x1104);
}

TEST(ParameterAreaRead, W342_5_3_7_ParameterErrors) {
    Harness h;
    EXPECT_EQ(h.send("0201 8011 0000 0001").end_code(), 0x1101);
    EXPECT_EQ(h.send("0201 0010 0000 0001").end_code(), 0x1101);
    EXPECT_EQ(h.send("0201 8010 0200 0001").end_code(), 0x1103);
    EXPECT_EQ(h.send("0201 8000 1F40 0000").end_code(), 0x1103);
    // "Bit 15 must be OFF (0) in the command format": 110C.
    EXPECT_EQ(h.send("0201 8010 0000 8001").end_code(), 0x110C);
    EXPECT_EQ(h.send("0201 8010 0000").end_code(), 0x1002);
    EXPECT_EQ(h.send("0201 8010 0000 0001 00").end_code(), 0x1001);
    const auto zero = h.send("0201 8012 0000 0000");
    EXPECT_EQ(zero.end_code(), 0x0000);
    EXPECT_EQ(zero.data_hex(), to_hex(hex("8012 0000 0000")));
}

TEST(ParameterAreaRead, W342_5_1_2_ReadsInEveryModeAndUnderProtection) {
    Harness h;
    h.plc.set_dip_write_protection(true);
    h.plc.set_um_read_protection(true);
    for (auto mode : {OperatingMode::run, OperatingMode::monitor, OperatingMode::program}) {
        h.plc.set_mode(mode);
        EXPECT_EQ(h.send("0201 8012 0000 0001").end_code(), 0x0000);
    }
}

TEST(ParameterAreaWrite, W342_5_3_8_RoutingTableWriteWithBit15OnTheLastWord) {
    Harness h;
    EXPECT_EQ(h.send(write_cmd(0x8013, 0x1FE, 2, true, 0x0A0B)).end_code(), 0x0000);
    EXPECT_EQ(h.send("0201 8013 01FE 0002").data_hex(), to_hex(hex("8013 01FE 8002 0A0B 0A0C")));
    EXPECT_EQ(h.send(write_cmd(0x8013, 0, 4, false, 1)).end_code(), 0x0000);
    EXPECT_EQ(h.plc.parameters().words(0x8013)[3], 4);
}

TEST(ParameterAreaWrite, W342_5_3_8_Bit15MustMatchTheLastWord) {
    Harness h;
    // Holding the last word without bit 15, or bit 15 without the last word: 110C,
    // nothing written.
    EXPECT_EQ(h.send(write_cmd(0x8013, 0x1FE, 2, false, 5)).end_code(), 0x110C);
    EXPECT_EQ(h.send(write_cmd(0x8013, 0x100, 2, true, 5)).end_code(), 0x110C);
    EXPECT_EQ(h.plc.parameters().words(0x8013)[0x1FE], 0);
    EXPECT_EQ(h.plc.parameters().words(0x8013)[0x100], 0);
}

TEST(ParameterAreaWrite, W342_5_3_8_ZeroWordsIsNormalAndWritesNothing) {
    Harness h;
    EXPECT_EQ(h.send("0202 8010 0000 0000").end_code(), 0x0000);
    EXPECT_EQ(h.send("0202 8010 0005 8000").end_code(), 0x0000);
    EXPECT_FALSE(h.plc.parameters().staging());
}

TEST(ParameterAreaWrite, W342_5_3_8_Over498WordsWritesNothingWith1001) {
    Harness h;
    EXPECT_EQ(h.send(write_cmd(0x8002, 0, 499, false, 1)).end_code(), 0x1001);
    EXPECT_FALSE(h.plc.parameters().staging());
}

TEST(ParameterAreaWrite, W342_5_3_8_RangeAndLengthErrors) {
    Harness h;
    EXPECT_EQ(h.send(write_cmd(0x8011, 0, 1, false)).end_code(), 0x1101);
    EXPECT_EQ(h.send(write_cmd(0x8013, 0x200, 1, false)).end_code(), 0x1103);
    EXPECT_EQ(h.send(write_cmd(0x8013, 0x1FF, 2, true)).end_code(), 0x1104);
    EXPECT_EQ(h.send("0202 8013 0000 0002 1234").end_code(), 0x1003);
    EXPECT_EQ(h.send("0202 8013 0000 0001 123456").end_code(), 0x1003);
    EXPECT_EQ(h.send("0202 8013 0000").end_code(), 0x1002);
}

TEST(ParameterAreaWrite, W342_5_3_7_WholeAreaWritesFollowEachOtherAndGoLiveAtTheEnd) {
    Harness h;
    EXPECT_EQ(h.send(write_cmd(0x8010, 0, 498, false, 0x100)).end_code(), 0x0000);
    EXPECT_EQ(h.plc.parameters().words(0x8010)[0], 0);  // staged only
    EXPECT_EQ(h.send(write_cmd(0x8010, 498, 14, true, 0x100 + 498)).end_code(), 0x0000);
    EXPECT_EQ(h.send("0201 8010 0000 0001").data_hex(), to_hex(hex("8010 0000 0001 0100")));
    // A single word inside a whole area, out of sequence: 110C.
    EXPECT_EQ(h.send(write_cmd(0x8010, 5, 1, false)).end_code(), 0x110C);
    EXPECT_EQ(write_whole(h, 0x8002, 5184, 3), 0);
    EXPECT_EQ(h.plc.parameters().words(0x8002)[5183], 3 + 5183);
}

TEST(ParameterAreaWrite, W342_5_3_8_IoTableOnlyInProgramMode) {
    Harness h;
    h.plc.set_mode(OperatingMode::run);
    EXPECT_EQ(h.send(write_cmd(0x8012, 0, 498, false)).end_code(), 0x2206);
    h.plc.set_mode(OperatingMode::monitor);
    EXPECT_EQ(h.send(write_cmd(0x8012, 0, 498, false)).end_code(), 0x2205);
    // Through 8000, only blocks touching 0400-08FF are refused.
    EXPECT_EQ(h.send(write_cmd(0x8000, 0, 498, false)).end_code(), 0x0000);
    EXPECT_EQ(h.send(write_cmd(0x8000, 498, 498, false)).end_code(), 0x0000);  // to 03E3
    EXPECT_EQ(h.send(write_cmd(0x8000, 996, 498, false)).end_code(), 0x2205);  // 03E4-05D5
    // The other areas are written in any mode (5-3-8 comments).
    EXPECT_EQ(write_whole(h, 0x8010, 512, 1), 0);
    h.plc.set_mode(OperatingMode::program);
    EXPECT_EQ(write_whole(h, 0x8012, 1280, 9), 0);
    EXPECT_EQ(h.plc.parameters().words(0x8012)[1279], 9 + 1279);
}

TEST(ParameterAreaWrite, W342_5_1_2_ExecutionConditions) {
    Harness h;
    h.plc.set_dip_write_protection(true);
    EXPECT_EQ(h.send(write_cmd(0x8013, 0, 1, false)).end_code(), 0x2101);
    h.plc.set_dip_write_protection(false);
    h.plc.set_um_read_protection(true);  // OK under UM read protection
    EXPECT_EQ(h.send(write_cmd(0x8013, 0, 1, false)).end_code(), 0x0000);
    h.plc.set_access_right_holder(NodeAddress{0x01, 0x63, 0x00});
    EXPECT_EQ(h.send(write_cmd(0x8013, 0, 1, false)).end_code(), 0x3001);
    EXPECT_EQ(h.send("0203 8013 0000 0200 0000").end_code(), 0x3001);
    EXPECT_EQ(h.send("0201 8013 0000 0001").end_code(), 0x0000);
}

TEST(ParameterAreaClear, W342_5_3_9_ClearsTheWholeArea) {
    Harness h;
    h.plc.parameters().words(0x8013)[7] = 7;
    EXPECT_EQ(h.send("0203 8013 0000 0200 0000").end_code(), 0x0000);
    EXPECT_EQ(h.plc.parameters().words(0x8013)[7], 0);
    h.plc.parameters().words(0x8000)[0x1F3F] = 1;
    h.plc.set_mode(OperatingMode::program);  // 8000 holds the I/O table
    EXPECT_EQ(h.send("0203 8000 0000 1F40 0000").end_code(), 0x0000);
    EXPECT_EQ(h.plc.parameters().words(0x8002)[0x143F], 0);
    // Bit 15 in the count is accepted (the whole area holds the last word).
    EXPECT_EQ(h.send("0203 8010 0000 8200 0000").end_code(), 0x0000);
}

TEST(ParameterAreaClear, W342_5_3_9_BeginningWordDataAndCountRules) {
    Harness h;
    h.plc.parameters().words(0x8010)[0] = 1;
    EXPECT_EQ(h.send("0203 8010 0000 0000 0000").end_code(), 0x0000);  // 0 words: nothing
    EXPECT_EQ(h.plc.parameters().words(0x8010)[0], 1);
    EXPECT_EQ(h.send("0203 8011 0000 0200 0000").end_code(), 0x1101);
    EXPECT_EQ(h.send("0203 8010 0001 0200 0000").end_code(), 0x1103);
    EXPECT_EQ(h.send("0203 8010 0000 0200 0001").end_code(), 0x110C);
    EXPECT_EQ(h.send("0203 8010 0000 0201 0000").end_code(), 0x1104);
    EXPECT_EQ(h.send("0203 8010 0000 01FF 0000").end_code(), 0x110C);
    EXPECT_EQ(h.plc.parameters().words(0x8010)[0], 1);
    EXPECT_EQ(h.send("0203 8010 0000 0200").end_code(), 0x1002);
    EXPECT_EQ(h.send("0203 8010 0000 0200 0000 00").end_code(), 0x1001);
}

TEST(ParameterAreaClear, W342_5_3_9_IoTableOnlyInProgramMode) {
    Harness h;
    h.plc.parameters().words(0x8012)[3] = 3;
    h.plc.set_mode(OperatingMode::run);
    EXPECT_EQ(h.send("0203 8012 0000 0500 0000").end_code(), 0x2206);
    EXPECT_EQ(h.send("0203 8000 0000 1F40 0000").end_code(), 0x2206);
    h.plc.set_mode(OperatingMode::monitor);
    EXPECT_EQ(h.send("0203 8012 0000 0500 0000").end_code(), 0x2205);
    EXPECT_EQ(h.plc.parameters().words(0x8012)[3], 3);
    EXPECT_EQ(h.send("0203 8010 0000 0200 0000").end_code(), 0x0000);  // PLC Setup: any mode
    h.plc.set_mode(OperatingMode::program);
    EXPECT_EQ(h.send("0203 8012 0000 0500 0000").end_code(), 0x0000);
    EXPECT_EQ(h.plc.parameters().words(0x8012)[3], 0);
}

}  // namespace
}  // namespace fins::test
