// 01 05 MEMORY AREA TRANSFER through full request frames (W342 5-3-6).
#include <gtest/gtest.h>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

TEST(MemoryAreaTransfer, W342_5_3_6_CopiesWordsBetweenAreas) {
    Harness h;
    auto dm = h.memory().words(Region::dm);
    dm[0] = 0x1111;
    dm[1] = 0x2222;
    const auto reply = h.send("0105 82000000 B0000A00 0002");
    EXPECT_EQ(reply.end_code(), 0x0000);
    EXPECT_TRUE(reply.data().empty());
    EXPECT_EQ(h.memory().words(Region::cio)[10], 0x1111);
    EXPECT_EQ(h.memory().words(Region::cio)[11], 0x2222);
    EXPECT_EQ(dm[0], 0x1111);
}

TEST(MemoryAreaTransfer, W342_5_3_6_OverlapBehavesAsACopyOfTheSource) {
    Harness h;
    auto dm = h.memory().words(Region::dm);
    for (std::uint16_t i = 0; i < 8; ++i)
        dm[i] = static_cast<std::uint16_t>(0x100 + i);
    EXPECT_EQ(h.send("0105 82000000 82000100 0004").end_code(), 0x0000);
    EXPECT_EQ(h.send("0101 82000000 0006").data_hex(),
              to_hex(hex("0100 0100 0101 0102 0103 0105")));
}

TEST(MemoryAreaTransfer, W342_5_3_6_CompletionFlagsAreNotTurnedOff) {
    Harness h;
    h.memory().set_completion_flag(1, true);
    h.memory().words(Region::dm)[0] = 0x0042;
    EXPECT_EQ(h.send("0105 82000000 89000100 0001").end_code(), 0x0000);
    EXPECT_EQ(h.memory().words(Region::timer_counter)[1], 0x0042);
    EXPECT_TRUE(h.memory().completion_flag(1));
}

TEST(MemoryAreaTransfer, W342_5_3_44_DestinationForcedBitsKeepTheirState) {
    Harness h;
    ASSERT_TRUE(h.memory().force_bit(Region::holding, 0, 8, true));
    h.memory().words(Region::dm)[0] = 0x0001;
    EXPECT_EQ(h.send("0105 82000000 B2000000 0001").end_code(), 0x0000);
    EXPECT_EQ(h.memory().words(Region::holding)[0], 0x0101);
}

TEST(MemoryAreaTransfer, W342_5_3_6_CountZeroCopiesNothing) {
    Harness h;
    h.memory().words(Region::dm)[0] = 0x0001;
    EXPECT_EQ(h.send("0105 82000000 82000100 0000").end_code(), 0x0000);
    EXPECT_EQ(h.memory().words(Region::dm)[1], 0);
}

TEST(MemoryAreaTransfer, W342_5_3_6_WordCodesOnlyElse1101) {
    Harness h;
    EXPECT_EQ(h.send("0105 30000000 82000000 0001").end_code(), 0x1101);
    EXPECT_EQ(h.send("0105 82000000 02000000 0001").end_code(), 0x1101);
    EXPECT_EQ(h.send("0105 DC010000 82000000 0001").end_code(), 0x1101);
    EXPECT_EQ(h.send("0105 82000000 BC020000 0001").end_code(), 0x1101);
}

TEST(MemoryAreaTransfer, W342_5_1_3_RangeErrorsSourceFirst) {
    Harness h;
    EXPECT_EQ(h.send("0105 82800000 FF000000 0001").end_code(), 0x1103);
    EXPECT_EQ(h.send("0105 82000000 82800000 0001").end_code(), 0x1103);
    EXPECT_EQ(h.send("0105 827FFF00 82000000 0002").end_code(), 0x1104);
    EXPECT_EQ(h.send("0105 82000000 827FFF00 0002").end_code(), 0x1104);
    EXPECT_EQ(h.send("0105 82000000 B0000000 1801").end_code(), 0x1104);
}

TEST(MemoryAreaTransfer, W342_5_2_2_ReadOnlyAuxiliaryIsASourceNotADestination) {
    Harness h;
    h.memory().words(Region::auxiliary)[0] = 0xA000;
    EXPECT_EQ(h.send("0105 B3000000 82000000 0001").end_code(), 0x0000);
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0xA000);
    EXPECT_EQ(h.send("0105 82000000 B3000000 0001").end_code(), 0x2101);
    EXPECT_EQ(h.memory().words(Region::auxiliary)[0], 0xA000);
}

TEST(MemoryAreaTransfer, W342_5_1_3_EmBankTheModelLacksIs1101) {
    plc::Profile p = plc::cj2h();
    p.em_banks = 1;
    Harness h(p);
    EXPECT_EQ(h.send("0105 A0000000 98000100 0001").end_code(), 0x0000);
    EXPECT_EQ(h.send("0105 A1000000 82000000 0001").end_code(), 0x1101);
    EXPECT_EQ(h.send("0105 82000000 61000000 0001").end_code(), 0x1101);
}

TEST(MemoryAreaTransfer, W342_5_1_3_ShortCommandIs1002LongIs1001) {
    Harness h;
    EXPECT_EQ(h.send("0105 82000000 82000100").end_code(), 0x1002);
    EXPECT_EQ(h.send("0105 82000000 82000100 0001 00").end_code(), 0x1001);
}

}  // namespace
}  // namespace fins::test
