// IoMemory storage sizes, profiles and address validation (locate), W342 5-2-2.
#include <gtest/gtest.h>

#include "plc/io_memory_test_util.hpp"
#include "plc/plc.hpp"

namespace fins::plc::test {
namespace {

TEST(Profile, W342_5_2_2_Cj2hDefaults) {
    const Profile p = cj2h();
    EXPECT_EQ(p.model, "CJ2H-CPU68-EIP");
    EXPECT_EQ(p.em_banks, 25);
    EXPECT_TRUE(p.cj2_em_codes);
    EXPECT_TRUE(p.cv_mode_codes);
}

TEST(IoMemory, W342_5_2_2_RegionSizes) {
    HeapMemory m(cj2h());
    EXPECT_EQ(m.words(Region::cio).size(), 6144U);
    EXPECT_EQ(m.words(Region::work).size(), 512U);
    EXPECT_EQ(m.words(Region::holding).size(), 512U);
    EXPECT_EQ(m.words(Region::auxiliary).size(), 960U);
    EXPECT_EQ(m.words(Region::dm).size(), 32768U);
    EXPECT_EQ(m.words(Region::timer_counter).size(), counter_base + 4096U);
    EXPECT_EQ(m.words(Region::data_register).size(), 16U);
    EXPECT_EQ(m.index_registers().size(), 16U);
    for (std::uint8_t bank = 0; bank < 25; ++bank)
        EXPECT_EQ(m.words(Region::em, bank).size(), 32768U) << int{bank};
    EXPECT_TRUE(m.words(Region::em, 25).empty());
    EXPECT_EQ(m.words(Region::em_current).size(), 32768U);
    EXPECT_EQ(m.forced_mask(Region::cio).size(), 6144U);
    EXPECT_EQ(m.forced_mask(Region::work).size(), 512U);
    EXPECT_EQ(m.forced_mask(Region::holding).size(), 512U);
    EXPECT_TRUE(m.forced_mask(Region::dm).empty());
    EXPECT_TRUE(m.words(Region::task_flag).empty());
}

TEST(IoMemory, ElementSizesAgreeWithTheAreaTable) {
    for (const auto& s : memory_area_table())
        EXPECT_EQ(element_bytes(s.kind), s.element_size) << s.name;
}

TEST(IoMemory, W342_5_2_2_LastAddressOfEveryAreaIsAccepted) {
    HeapMemory m(cj2h());
    EXPECT_EQ(code_of(m.locate(at(0xB0, 6143), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x30, 6143, 15), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0xB1, 511), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0xB2, 511), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0xB3, 959), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x82, 32767), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x89, 0x0FFF), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x89, 0x8FFF), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x68, 32767), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0xDC, 0x010F), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0xBC, 0x020F), 1, use_read, Intent::read)), 0);
}

TEST(IoMemory, LocateMapsCountersAfterTimers) {
    HeapMemory m(cj2h());
    const auto r = m.locate(at(0x89, 0x8005), 1, use_read, Intent::read);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->index, counter_base + 5);
    EXPECT_EQ(r->region, Region::timer_counter);
}

TEST(IoMemory, W342_5_1_3_UnknownOrUnlistedCodeIs1101) {
    HeapMemory m(cj2h());
    EXPECT_EQ(code_of(m.locate(at(0xFF, 0), 1, use_read, Intent::read)), 0x1101);
    EXPECT_EQ(code_of(m.locate(at(0x09, 0), 1, use_write, Intent::write)), 0x1101);
    EXPECT_EQ(code_of(m.locate(at(0x30, 0), 1, use_word_ops, Intent::write)), 0x1101);
    EXPECT_EQ(code_of(m.locate(at(0x70, 0), 1, use_read, Intent::read)), 0x1101);
    // BC: DR is writable, the current EM bank number is not.
    EXPECT_EQ(code_of(m.locate(at(0xBC, 0x0F00), 1, use_write, Intent::write)), 0x1101);
    // Outside every segment of a code no segment of which the command lists.
    EXPECT_EQ(code_of(m.locate(at(0x09, 0x5000), 1, use_write, Intent::write)), 0x1101);
}

TEST(IoMemory, W342_5_1_3_StartOutsideTheAreaIs1103) {
    HeapMemory m(cj2h());
    EXPECT_EQ(code_of(m.locate(at(0xB0, 6144), 1, use_read, Intent::read)), 0x1103);
    EXPECT_EQ(code_of(m.locate(at(0x82, 0x8000), 1, use_read, Intent::read)), 0x1103);
    EXPECT_EQ(code_of(m.locate(at(0x89, 0x1000), 1, use_read, Intent::read)), 0x1103);
    EXPECT_EQ(code_of(m.locate(at(0xBC, 0x0300), 1, use_write, Intent::write)), 0x1103);
    EXPECT_EQ(code_of(m.locate(at(0x07, 0x100B), 1, use_read, Intent::read)), 0x1103);
}

TEST(IoMemory, W342_5_2_1_BitNumberChecksAre1103) {
    HeapMemory m(cj2h());
    EXPECT_EQ(code_of(m.locate(at(0x30, 10, 0x10), 1, use_read, Intent::read)), 0x1103);
    EXPECT_EQ(code_of(m.locate(at(0x30, 10, 0x0F), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x82, 10, 0x01), 1, use_read, Intent::read)), 0x1103);
    // "Always 00 hex for word address and Timer/Counter Completion Flags."
    EXPECT_EQ(code_of(m.locate(at(0x09, 10, 0x01), 1, use_read, Intent::read)), 0x1103);
}

TEST(IoMemory, W342_5_1_3_EndPastTheAreaIs1104) {
    HeapMemory m(cj2h());
    EXPECT_EQ(code_of(m.locate(at(0x82, 32767), 2, use_read, Intent::read)), 0x1104);
    EXPECT_EQ(code_of(m.locate(at(0x82, 32000), 768, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x82, 32000), 769, use_read, Intent::read)), 0x1104);
    EXPECT_EQ(code_of(m.locate(at(0x30, 6143, 15), 2, use_read, Intent::read)), 0x1104);
    EXPECT_EQ(code_of(m.locate(at(0x30, 6143, 14), 2, use_read, Intent::read)), 0);
    // Timers and counters are separate segments of code 09/89.
    EXPECT_EQ(code_of(m.locate(at(0x89, 0x0FFF), 2, use_read, Intent::read)), 0x1104);
}

TEST(IoMemory, CountZeroValidatesTheStartOnly) {
    HeapMemory m(cj2h());
    const auto r = m.locate(at(0x82, 32767), 0, use_read, Intent::read);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->byte_size(), 0U);
    EXPECT_EQ(code_of(m.locate(at(0x82, 0x8000), 0, use_read, Intent::read)), 0x1103);
    // Nothing is written, so a read-only start is not refused.
    EXPECT_EQ(code_of(m.locate(at(0xB3, 0), 0, use_write, Intent::write)), 0);
}

TEST(IoMemory, W342_5_2_2_AuxiliaryA000ToA447IsReadOnly) {
    HeapMemory m(cj2h());
    EXPECT_EQ(code_of(m.locate(at(0xB3, 447), 1, use_write, Intent::write)), 0x2101);
    EXPECT_EQ(code_of(m.locate(at(0xB3, 448), 1, use_write, Intent::write)), 0);
    EXPECT_EQ(code_of(m.locate(at(0xB3, 447), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x33, 447, 15), 2, use_write, Intent::write)), 0x2101);
    // CV mode: A448 is word 0CC0.
    EXPECT_EQ(code_of(m.locate(at(0x80, 0x0CBF), 1, use_write, Intent::write)), 0x2101);
    EXPECT_EQ(code_of(m.locate(at(0x80, 0x0CC0), 1, use_write, Intent::write)), 0);
}

TEST(IoMemory, W342_5_1_3_EmBankTheModelLacksIs1101) {
    Profile p = cj2h();
    p.em_banks = 3;
    HeapMemory m(p);
    EXPECT_EQ(code_of(m.locate(at(0xA2, 0), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0xA3, 0), 1, use_read, Intent::read)), 0x1101);
    EXPECT_EQ(code_of(m.locate(at(0x23, 0), 1, use_write, Intent::write)), 0x1101);
    EXPECT_EQ(code_of(m.locate(at(0x68, 0), 1, use_read, Intent::read)), 0x1101);
    EXPECT_EQ(code_of(m.locate(at(0x53, 0, 0), 1, use_read, Intent::read)), 0x1101);
    EXPECT_FALSE(m.set_current_em_bank(3));
    EXPECT_TRUE(m.set_current_em_bank(2));
}

TEST(IoMemory, W342_5_1_3_NoEmAtAllMakesCurrentBankCodes1101) {
    Profile p = cj2h();
    p.em_banks = 0;
    HeapMemory m(p);
    EXPECT_EQ(code_of(m.locate(at(0x98, 0), 1, use_read, Intent::read)), 0x1101);
    EXPECT_EQ(code_of(m.locate(at(0x0A, 0, 3), 1, use_read, Intent::read)), 0x1101);
    EXPECT_EQ(code_of(m.locate(at(0xBC, 0x0F00), 1, use_read, Intent::read)), 0x1101);
    EXPECT_EQ(code_of(m.locate(at(0xBC, 0x0200), 1, use_read, Intent::read)), 0);
}

TEST(IoMemory, W342_5_2_2_Note2_Cj2OnlyEmCodes) {
    HeapMemory cj2(cj2h());
    EXPECT_EQ(code_of(cj2.locate(at(0x53, 0), 1, use_read, Intent::read)), 0);
    Profile p = cj2h();
    p.cj2_em_codes = false;
    HeapMemory other(p);
    EXPECT_EQ(code_of(other.locate(at(0x53, 0), 1, use_read, Intent::read)), 0x1101);
    EXPECT_EQ(code_of(other.locate(at(0xA3, 0), 1, use_read, Intent::read)), 0);
}

TEST(IoMemory, W342_5_2_2_CvModeCodesFollowTheProfile) {
    Profile p = cj2h();
    p.cv_mode_codes = false;
    HeapMemory m(p);
    EXPECT_EQ(code_of(m.locate(at(0x80, 0), 1, use_read, Intent::read)), 0x1101);
    EXPECT_EQ(code_of(m.locate(at(0x90, 0), 1, use_read, Intent::read)), 0x1101);
    // 82 and 98 are CS/CJ codes as well.
    EXPECT_EQ(code_of(m.locate(at(0x82, 0), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x98, 0), 1, use_read, Intent::read)), 0);
}

TEST(IoMemory, SmallerModelSizesBoundAddresses) {
    Profile p = cj2h();
    p.dm_words = 10000;
    p.timers = 256;
    HeapMemory m(p);
    EXPECT_EQ(code_of(m.locate(at(0x82, 9999), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x82, 10000), 1, use_read, Intent::read)), 0x1103);
    EXPECT_EQ(code_of(m.locate(at(0x82, 9990), 11, use_read, Intent::read)), 0x1104);
    EXPECT_EQ(code_of(m.locate(at(0x89, 255), 1, use_read, Intent::read)), 0);
    EXPECT_EQ(code_of(m.locate(at(0x89, 256), 1, use_read, Intent::read)), 0x1103);
    EXPECT_EQ(code_of(m.locate(at(0x89, 0x8000), 1, use_read, Intent::read)), 0);
}

TEST(IoMemory, EveryCodeAndWordNeverEscapesStorage) {
    // Exhaustive over code x word at the edges: locate+read must stay in bounds (ASan).
    Profile p = cj2h();
    p.em_banks = 2;
    p.dm_words = 100;
    HeapMemory m(p);
    for (unsigned code = 0; code < 256; ++code)
        for (unsigned word : {0U, 1U, 99U, 100U, 0x01FFU, 0x0F00U, 0x7FFFU, 0x8FFFU, 0xFFFFU})
            for (unsigned count : {0U, 1U, 2U, 17U, 1000U, 65535U}) {
                const auto r = m.locate(
                    at(static_cast<std::uint8_t>(code), static_cast<std::uint16_t>(word), 0), count,
                    use_multi_read, Intent::read);
                if (!r) continue;
                std::vector<std::uint8_t> out(r->byte_size());
                ByteWriter w(out);
                m.read(*r, w, {});
                EXPECT_FALSE(w.overflowed());
            }
}

TEST(Plc, DefaultsToRunModeWithNothingProtected) {
    Plc plc;
    EXPECT_EQ(plc.mode(), OperatingMode::run);
    EXPECT_EQ(plc.profile().model, "CJ2H-CPU68-EIP");
    EXPECT_FALSE(plc.access_right_holder().has_value());
    EXPECT_FALSE(plc.network_write_protection());
    EXPECT_FALSE(plc.um_read_protection());
    EXPECT_FALSE(plc.dip_write_protection());
    EXPECT_EQ(plc.memory().current_em_bank(), 0);
}

TEST(Plc, AccessRightHeldByOtherComparesTheWholeAddress) {
    Plc plc;
    plc.set_access_right_holder(NodeAddress{1, 5, 0});
    EXPECT_FALSE(plc.access_right_held_by_other(NodeAddress{1, 5, 0}));
    EXPECT_TRUE(plc.access_right_held_by_other(NodeAddress{1, 6, 0}));
    plc.set_access_right_holder(std::nullopt);
    EXPECT_FALSE(plc.access_right_held_by_other(NodeAddress{1, 6, 0}));
}

}  // namespace
}  // namespace fins::plc::test
