// IoMemory element encodings (W342 5-2-1), forcing, write/fill/transfer semantics
// (W342 5-3-3, 5-3-4, 5-3-6) and the derived area 07 flags.
#include <gtest/gtest.h>

#include <chrono>

#include "plc/io_memory_test_util.hpp"

namespace fins::plc::test {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

TimePoint after(std::chrono::system_clock::duration d) {
    return TimePoint{} + d;
}

TEST(IoMemory, W342_5_2_1_WordsAreBigEndian) {
    HeapMemory m(cj2h());
    m.words(Region::dm)[10] = 0x1234;
    m.words(Region::dm)[11] = 0xABCD;
    EXPECT_EQ(read(m, at(0x82, 10), 2), (Bytes8{0x12, 0x34, 0xAB, 0xCD}));
}

TEST(IoMemory, W342_5_2_1_BitRunsContinueIntoTheNextWord) {
    HeapMemory m(cj2h());
    m.words(Region::cio)[10] = 0x8000;  // CIO10.15
    m.words(Region::cio)[11] = 0x0002;  // CIO11.01
    EXPECT_EQ(read(m, at(0x30, 10, 15), 3), (Bytes8{1, 0, 1}));
    ASSERT_EQ(write(m, at(0x30, 20, 15), 2, {1, 1}), 0);
    EXPECT_EQ(m.words(Region::cio)[20], 0x8000);
    EXPECT_EQ(m.words(Region::cio)[21], 0x0001);
}

TEST(IoMemory, BitWriteTakesAnyNonZeroByteAsOn) {
    HeapMemory m(cj2h());
    ASSERT_EQ(write(m, at(0x02, 5, 0), 3, {0x00, 0x01, 0xFF}), 0);
    EXPECT_EQ(m.words(Region::dm)[5], 0x0006);
}

TEST(IoMemory, W342_5_2_1_DoubleWordIndexRegisterIsBigEndian) {
    HeapMemory m(cj2h());
    m.index_registers()[3] = 0x01020304;
    EXPECT_EQ(read(m, at(0xDC, 0x0103), 1), (Bytes8{1, 2, 3, 4}));
    ASSERT_EQ(write(m, at(0xDC, 0x0100), 1, {0xDE, 0xAD, 0xBE, 0xEF}), 0);
    EXPECT_EQ(m.index_registers()[0], 0xDEADBEEFU);
}

TEST(IoMemory, W342_5_2_2_RegistersTasksAndEmBankNumber) {
    HeapMemory m(cj2h());
    m.words(Region::data_register)[15] = 0x0F0F;
    m.set_task_flag(31, true);
    m.set_task_status(2, 0x81);
    ASSERT_TRUE(m.set_current_em_bank(0x18));
    EXPECT_EQ(read(m, at(0xBC, 0x020F), 1), (Bytes8{0x0F, 0x0F}));
    EXPECT_EQ(read(m, at(0x06, 0x001E), 2), (Bytes8{0, 1}));
    EXPECT_EQ(read(m, at(0x46, 0x0002), 1), (Bytes8{0x81}));
    EXPECT_EQ(read(m, at(0xBC, 0x0F00), 1), (Bytes8{0x00, 0x18}));
    EXPECT_EQ(read(m, at(0x9C, 0x0006), 1), (Bytes8{0x00, 0x18}));
}

TEST(IoMemory, W342_5_2_2_CurrentEmBankIsTheSelectedBank) {
    HeapMemory m(cj2h());
    m.words(Region::em, 0)[7] = 0x0007;
    m.words(Region::em, 5)[7] = 0x0507;
    EXPECT_EQ(read(m, at(0x98, 7), 1), (Bytes8{0x00, 0x07}));
    ASSERT_TRUE(m.set_current_em_bank(5));
    EXPECT_EQ(read(m, at(0x98, 7), 1), (Bytes8{0x05, 0x07}));
    ASSERT_EQ(write(m, at(0x0A, 7, 15), 1, {1}), 0);
    EXPECT_EQ(m.words(Region::em, 5)[7], 0x8507);
}

TEST(IoMemory, W342_5_2_1_ForcedStatusEncodings) {
    HeapMemory m(cj2h());
    ASSERT_TRUE(m.force_bit(Region::cio, 10, 3, true));
    ASSERT_TRUE(m.force_bit(Region::cio, 10, 4, false));
    m.words(Region::cio)[10] |= 0x0001;
    // Bit with forced status: bit 0 value, bit 1 forced.
    EXPECT_EQ(read(m, at(0x70, 10, 0), 5), (Bytes8{0x01, 0x00, 0x00, 0x03, 0x02}));
    // Word with forced status: forced mask word, then value word.
    EXPECT_EQ(read(m, at(0xF0, 10), 1), (Bytes8{0x00, 0x18, 0x00, 0x09}));
    ASSERT_TRUE(m.force_completion_flag(counter_base + 1, true));
    EXPECT_EQ(read(m, at(0x49, 0x8000), 2), (Bytes8{0x00, 0x03}));
    EXPECT_EQ(read(m, at(0x09, 0x8001), 1), (Bytes8{0x01}));
}

TEST(IoMemory, W342_5_3_3_WritesDoNotChangeForcedBits) {
    HeapMemory m(cj2h());
    ASSERT_TRUE(m.force_bit(Region::work, 3, 0, true));
    ASSERT_TRUE(m.force_bit(Region::work, 3, 15, false));
    ASSERT_EQ(write(m, at(0xB1, 3), 1, {0xFF, 0xFE}), 0);
    EXPECT_EQ(m.words(Region::work)[3], 0x7FFF);
    ASSERT_EQ(write(m, at(0xB1, 3), 1, {0x00, 0x00}), 0);
    EXPECT_EQ(m.words(Region::work)[3], 0x0001);
    ASSERT_EQ(write(m, at(0x31, 3, 0), 1, {0x00}), 0);
    EXPECT_EQ(m.words(Region::work)[3], 0x0001);
    ASSERT_TRUE(m.release_bit(Region::work, 3, 0));
    ASSERT_EQ(write(m, at(0x31, 3, 0), 1, {0x00}), 0);
    EXPECT_EQ(m.words(Region::work)[3], 0x0000);
    EXPECT_TRUE(m.is_forced(Region::work, 3, 15));
    m.release_all_forced();
    EXPECT_FALSE(m.is_forced(Region::work, 3, 15));
}

TEST(IoMemory, ForcingOnlyAppliesToCioWorkHoldingAndCompletionFlags) {
    HeapMemory m(cj2h());
    EXPECT_FALSE(m.force_bit(Region::dm, 0, 0, true));
    EXPECT_FALSE(m.force_bit(Region::auxiliary, 500, 0, true));
    EXPECT_FALSE(m.force_bit(Region::cio, 6144, 0, true));
    EXPECT_FALSE(m.force_bit(Region::cio, 0, 16, true));
    EXPECT_FALSE(m.force_completion_flag(counter_base + 4096, true));
    EXPECT_TRUE(m.force_bit(Region::holding, 511, 15, true));
    EXPECT_EQ(m.words(Region::holding)[511], 0x8000);
}

TEST(IoMemory, W342_5_3_3_WriteLengthMismatchIs1003AndWritesNothing) {
    HeapMemory m(cj2h());
    EXPECT_EQ(write(m, at(0x82, 0), 2, {0x11, 0x11, 0x22}), 0x1003);
    EXPECT_EQ(write(m, at(0x82, 0), 2, {0x11, 0x11, 0x22, 0x22, 0x33}), 0x1003);
    EXPECT_EQ(m.words(Region::dm)[0], 0);
    EXPECT_EQ(write(m, at(0x82, 0), 0, {0x11}), 0x1003);
    EXPECT_EQ(write(m, at(0x82, 0), 0, {}), 0);
}

TEST(IoMemory, W342_5_3_3_PvWriteLeavesCompletionFlags) {
    HeapMemory m(cj2h());
    m.set_completion_flag(7, true);
    ASSERT_EQ(write(m, at(0x89, 7), 1, {0x01, 0x00}), 0);
    EXPECT_EQ(m.words(Region::timer_counter)[7], 0x0100);
    EXPECT_TRUE(m.completion_flag(7));
}

TEST(IoMemory, W342_5_3_4_FillOnPvsTurnsCompletionFlagsOffExceptForced) {
    HeapMemory m(cj2h());
    for (std::uint32_t i = counter_base; i < counter_base + 4; ++i)
        m.set_completion_flag(i, true);
    ASSERT_TRUE(m.force_completion_flag(counter_base + 2, true));
    const auto r = m.locate(at(0x89, 0x8000), 3, use_word_ops, Intent::write);
    ASSERT_TRUE(r);
    EXPECT_EQ(m.fill(*r, 0x0042), EndCode::normal_completion);
    EXPECT_FALSE(m.completion_flag(counter_base + 0));
    EXPECT_FALSE(m.completion_flag(counter_base + 1));
    EXPECT_TRUE(m.completion_flag(counter_base + 2));  // forced ON stays ON
    EXPECT_TRUE(m.completion_flag(counter_base + 3));  // outside the range
    EXPECT_EQ(m.words(Region::timer_counter)[counter_base + 2], 0x0042);
}

TEST(IoMemory, W342_5_3_4_FillKeepsForcedBits) {
    HeapMemory m(cj2h());
    ASSERT_TRUE(m.force_bit(Region::cio, 1, 0, false));
    const auto r = m.locate(at(0xB0, 0), 3, use_word_ops, Intent::write);
    ASSERT_TRUE(r);
    EXPECT_EQ(m.fill(*r, 0xFFFF), EndCode::normal_completion);
    EXPECT_EQ(m.words(Region::cio)[0], 0xFFFF);
    EXPECT_EQ(m.words(Region::cio)[1], 0xFFFE);
    EXPECT_EQ(m.words(Region::cio)[2], 0xFFFF);
    EXPECT_EQ(m.words(Region::cio)[3], 0x0000);
}

EndCode transfer(IoMemory& m, MemoryAddress from, MemoryAddress to, std::uint32_t count) {
    const auto s = m.locate(from, count, use_word_ops, Intent::read);
    const auto d = m.locate(to, count, use_word_ops, Intent::write);
    if (!s || !d) return EndCode::area_classification_missing;
    return m.transfer(*s, *d);
}

TEST(IoMemory, W342_5_3_6_OverlappingTransferCopiesTheSourceFirst) {
    HeapMemory m(cj2h());
    auto dm = m.words(Region::dm);
    for (std::uint16_t i = 0; i < 6; ++i)
        dm[i] = static_cast<std::uint16_t>(i + 1);
    ASSERT_EQ(transfer(m, at(0x82, 0), at(0x82, 2), 4), EndCode::normal_completion);
    EXPECT_EQ((std::vector<std::uint16_t>(dm.begin(), dm.begin() + 6)),
              (std::vector<std::uint16_t>{1, 2, 1, 2, 3, 4}));
    ASSERT_EQ(transfer(m, at(0x82, 2), at(0x82, 1), 4), EndCode::normal_completion);
    EXPECT_EQ((std::vector<std::uint16_t>(dm.begin(), dm.begin() + 6)),
              (std::vector<std::uint16_t>{1, 1, 2, 3, 4, 4}));
}

TEST(IoMemory, W342_5_3_6_TransferBetweenABankAndTheCurrentBankOverlaps) {
    HeapMemory m(cj2h());
    ASSERT_TRUE(m.set_current_em_bank(3));
    auto e3 = m.words(Region::em, 3);
    for (std::uint16_t i = 0; i < 4; ++i)
        e3[i] = static_cast<std::uint16_t>(0x30 + i);
    ASSERT_EQ(transfer(m, at(0xA3, 0), at(0x98, 1), 3), EndCode::normal_completion);
    EXPECT_EQ((std::vector<std::uint16_t>(e3.begin(), e3.begin() + 4)),
              (std::vector<std::uint16_t>{0x30, 0x30, 0x31, 0x32}));
}

TEST(IoMemory, W342_5_3_6_TransferKeepsForcedBitsAndCompletionFlags) {
    HeapMemory m(cj2h());
    m.words(Region::dm)[0] = 0x0000;
    m.words(Region::dm)[1] = 0x1234;
    m.words(Region::cio)[100] = 0xFFFF;
    ASSERT_TRUE(m.force_bit(Region::cio, 100, 15, true));
    m.set_completion_flag(9, true);
    ASSERT_EQ(transfer(m, at(0x82, 0), at(0xB0, 100), 1), EndCode::normal_completion);
    EXPECT_EQ(m.words(Region::cio)[100], 0x8000);
    ASSERT_EQ(transfer(m, at(0x82, 1), at(0x89, 9), 1), EndCode::normal_completion);
    EXPECT_EQ(m.words(Region::timer_counter)[9], 0x1234);
    EXPECT_TRUE(m.completion_flag(9));
}

TEST(IoMemory, W342_5_2_2_ClockPulsesAreOnForTheFirstHalfOfEachPeriod) {
    using P = ClockPulse;
    EXPECT_TRUE(IoMemory::clock_pulse(P::one_second, after(milliseconds(250))));
    EXPECT_FALSE(IoMemory::clock_pulse(P::one_second, after(milliseconds(750))));
    EXPECT_TRUE(IoMemory::clock_pulse(P::one_minute, after(seconds(29))));
    EXPECT_FALSE(IoMemory::clock_pulse(P::one_minute, after(seconds(31))));
    EXPECT_TRUE(IoMemory::clock_pulse(P::point_two_second, after(milliseconds(1099))));
    EXPECT_FALSE(IoMemory::clock_pulse(P::point_two_second, after(milliseconds(1100))));
    EXPECT_TRUE(IoMemory::clock_pulse(P::point_one_second, after(milliseconds(40))));
    EXPECT_FALSE(IoMemory::clock_pulse(P::point_one_second, after(milliseconds(60))));
    EXPECT_TRUE(IoMemory::clock_pulse(P::point_zero_two_second, after(milliseconds(5))));
    EXPECT_FALSE(IoMemory::clock_pulse(P::point_zero_two_second, after(milliseconds(15))));
    // Before the epoch the phase still counts forward: -0.25 s is 0.75 s into a second.
    EXPECT_FALSE(IoMemory::clock_pulse(P::one_second, after(milliseconds(-250))));
}

TEST(IoMemory, W342_5_2_2_Area07ReadsPulsesAndConditionFlags) {
    HeapMemory m(cj2h());
    EXPECT_EQ(read(m, at(0x07, 0x0000), 5, after(milliseconds(1705))), (Bytes8{1, 0, 0, 1, 1}));
    EXPECT_EQ(read(m, at(0x07, 0x1000), 11), Bytes8(11, 0));
    EXPECT_EQ(read(m, at(0x07, 0x100E), 2), (Bytes8{0, 1}));  // Always OFF, Always ON
    EXPECT_EQ(read(m, at(0x07, 0x2001), 1), (Bytes8{0}));
    m.set_access_error_flag(true);
    EXPECT_EQ(read(m, at(0x07, 0x2001), 1), (Bytes8{1}));
}

}  // namespace
}  // namespace fins::plc::test
