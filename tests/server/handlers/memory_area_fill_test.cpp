// 01 03 MEMORY AREA FILL through full request frames (W342 5-3-4).
#include <gtest/gtest.h>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

TEST(MemoryAreaFill, W342_5_3_4_FillsConsecutiveWords) {
    Harness h;
    const auto reply = h.send("0103 82000A00 0003 ABCD");
    EXPECT_EQ(reply.end_code(), 0x0000);
    EXPECT_TRUE(reply.data().empty());
    const auto dm = h.memory().words(Region::dm);
    EXPECT_EQ(dm[9], 0);
    EXPECT_EQ(dm[10], 0xABCD);
    EXPECT_EQ(dm[12], 0xABCD);
    EXPECT_EQ(dm[13], 0);
}

TEST(MemoryAreaFill, W342_5_3_4_EveryWordCodeOfItsTable) {
    for (const char* address :
         {"B0 0000 00", "B1 0000 00", "B2 0000 00", "B3 01C0 00", "89 0000 00",
          "89 8000 00", "82 0000 00", "A0 0000 00", "AF 0000 00", "50 0000 00",
          "5F 0000 00", "60 0000 00", "68 0000 00", "98 0000 00", "80 0000 00",
          "80 0CC0 00", "81 0000 00", "81 0800 00", "90 0000 00", "97 0000 00"}) {
        Harness h;
        EXPECT_EQ(h.send(std::string("0103 ") + address + " 0002 1234").end_code(), 0x0000)
            << address;
        EXPECT_EQ(h.send(std::string("0101 ") + address + " 0002").data_hex(), "12 34 12 34")
            << address;
    }
}

TEST(MemoryAreaFill, W342_5_3_4_BitAndNonWordCodesAre1101) {
    Harness h;
    for (const char* address :
         {"30000000", "02000000", "20000000", "0A000000", "09000000", "BC020000", "DC010000",
          "06000000", "07000000", "F0000000", "FF000000"})
        EXPECT_EQ(h.send(std::string("0103 ") + address + " 0001 1234").end_code(), 0x1101)
            << address;
}

TEST(MemoryAreaFill, W342_5_3_4_FillOnTimerPvTurnsCompletionFlagsOff) {
    Harness h;
    auto& m = h.memory();
    for (std::uint32_t i = 0; i < 4; ++i)
        m.set_completion_flag(i, true);
    m.set_completion_flag(plc::counter_base, true);
    EXPECT_EQ(h.send("0103 89000000 0003 0100").end_code(), 0x0000);
    EXPECT_FALSE(m.completion_flag(0));
    EXPECT_FALSE(m.completion_flag(2));
    EXPECT_TRUE(m.completion_flag(3));
    EXPECT_TRUE(m.completion_flag(plc::counter_base));
    EXPECT_EQ(h.send("0103 89800000 0001 0100").end_code(), 0x0000);
    EXPECT_FALSE(m.completion_flag(plc::counter_base));
    EXPECT_EQ(h.send("0101 09000000 0004").data_hex(), "00 00 00 01");
}

TEST(MemoryAreaFill, W342_5_3_4_ForcedBitsKeepTheirState) {
    Harness h;
    ASSERT_TRUE(h.memory().force_bit(Region::cio, 5, 15, false));
    ASSERT_TRUE(h.memory().force_completion_flag(7, true));
    EXPECT_EQ(h.send("0103 B0000500 0001 FFFF").end_code(), 0x0000);
    EXPECT_EQ(h.memory().words(Region::cio)[5], 0x7FFF);
    EXPECT_EQ(h.send("0103 89000700 0001 0000").end_code(), 0x0000);
    EXPECT_TRUE(h.memory().completion_flag(7));
}

TEST(MemoryAreaFill, W342_5_3_4_CountZeroFillsNothing) {
    Harness h;
    EXPECT_EQ(h.send("0103 82000000 0000 FFFF").end_code(), 0x0000);
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0);
}

TEST(MemoryAreaFill, W342_5_1_3_RangeAndProtectionErrors) {
    Harness h;
    EXPECT_EQ(h.send("0103 82800000 0001 0000").end_code(), 0x1103);
    EXPECT_EQ(h.send("0103 82000001 0001 0000").end_code(), 0x1103);
    EXPECT_EQ(h.send("0103 827FF000 0011 0000").end_code(), 0x1104);
    EXPECT_EQ(h.send("0103 827FF000 0010 0000").end_code(), 0x0000);
    EXPECT_EQ(h.send("0103 B3000000 0001 0000").end_code(), 0x2101);
    EXPECT_EQ(h.send("0103 B301BF00 0002 FFFF").end_code(), 0x2101);
    EXPECT_EQ(h.memory().words(Region::auxiliary)[448], 0);
}

TEST(MemoryAreaFill, W342_5_1_3_EmBankTheModelLacksIs1101) {
    plc::Profile p = plc::cj2h();
    p.em_banks = 1;
    Harness h(p);
    EXPECT_EQ(h.send("0103 A0000000 0001 0001").end_code(), 0x0000);
    EXPECT_EQ(h.send("0103 A1000000 0001 0001").end_code(), 0x1101);
}

TEST(MemoryAreaFill, W342_5_1_3_ShortCommandIs1002LongIs1001) {
    Harness h;
    EXPECT_EQ(h.send("0103 82000000 0001").end_code(), 0x1002);
    EXPECT_EQ(h.send("0103 82000000 0001 00").end_code(), 0x1002);
    EXPECT_EQ(h.send("0103 82000000 0001 0000 00").end_code(), 0x1001);
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0);
}

}  // namespace
}  // namespace fins::test
