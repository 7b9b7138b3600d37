// 22 0A / 22 0B / 22 0C through full request frames (W342 5-3-39 .. 5-3-41): data
// files with the 48-byte header, transfer both ways and compare, the 5-1-2 notes (no
// file -> parameter or program area outside PROGRAM mode or under DIP protection).
#include <gtest/gtest.h>

#include "server/handlers/file_support.hpp"

namespace fins::test {
namespace {

using plc::OperatingMode;

MemoryAreaFileTransfer dm(std::uint16_t mode, std::uint16_t word, std::uint16_t count,
                          std::string_view name = "D.IOM") {
    return {mode, {0x82, word, 0}, count, disk_memory_card, file(name), ""};
}

TEST(MemoryAreaFileTransfer, W342_5_3_39_SaveLoadCompare) {
    Harness h;
    auto dm_words = h.memory().words(Region::dm);
    dm_words[100] = 0x1234;
    dm_words[101] = 0xABCD;
    auto r = run(h, dm(0, 100, 2));
    ASSERT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "00 02");
    // The file: 48-byte header, then the words high byte first.
    r = run(h, SingleFileRead{disk_memory_card, file("D.IOM"), 48, 10, ""});
    ASSERT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "00 00 00 34 00 00 00 30 80 04 12 34 AB CD");
    // Never overwrites (5-3-39 comment).
    EXPECT_EQ(run(h, dm(0, 100, 2)).end_code(), 0x2107);
    // Compare: equal, then a difference in the second word.
    r = run(h, dm(2, 100, 2));
    EXPECT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "00 02");
    dm_words[101] = 0;
    r = run(h, dm(2, 100, 2));
    EXPECT_EQ(r.end_code(), 0x2007);
    EXPECT_EQ(r.data_hex(), "00 01");
    // Load into D200: as many words as the file holds.
    r = run(h, dm(1, 200, 5));
    ASSERT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "00 02");
    EXPECT_EQ(dm_words[200], 0x1234);
    EXPECT_EQ(dm_words[201], 0xABCD);
    EXPECT_EQ(run(h, dm(1, 200, 2, "NONE.IOM")).end_code(), 0x2006);
    EXPECT_EQ(run(h, dm(3, 200, 2)).end_code(), 0x110C);
    EXPECT_EQ(run(h, dm(0, 32767, 2, "E.IOM")).end_code(), 0x1104);
    // Bit areas are not in the 5-3-39 table.
    MemoryAreaFileTransfer bits = dm(0, 0, 1, "B.IOM");
    bits.start.area_code = 0x02;
    EXPECT_EQ(run(h, bits).end_code(), 0x1101);
}

ParameterAreaFileTransfer setup(std::uint16_t mode) {
    return {mode, 0x8010, 0, whole_parameter_area, disk_memory_card, file("P.STD"), ""};
}

TEST(ParameterAreaFileTransfer, W342_5_3_40_SaveLoadCompareAndModes) {
    Harness h;
    auto words = h.plc.parameters().words(0x8010);
    words[0] = 0x5A5A;
    auto r = run(h, setup(0));
    ASSERT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "02 00");  // 512 words
    EXPECT_EQ(run(h, setup(2)).end_code(), 0x0000);
    words[3] = 1;
    r = run(h, setup(2));
    EXPECT_EQ(r.end_code(), 0x2007);
    EXPECT_EQ(r.data_hex(), "00 03");  // the first mismatch
    // File -> parameter area: PROGRAM mode only, not under DIP protection.
    h.plc.set_mode(OperatingMode::run);
    EXPECT_EQ(run(h, setup(1)).end_code(), 0x2206);
    h.plc.set_mode(OperatingMode::monitor);
    EXPECT_EQ(run(h, setup(1)).end_code(), 0x2205);
    h.plc.set_mode(OperatingMode::program);
    h.plc.set_dip_write_protection(true);
    EXPECT_EQ(run(h, setup(1)).end_code(), 0x2101);
    h.plc.set_dip_write_protection(false);
    EXPECT_EQ(run(h, setup(1)).end_code(), 0x0000);
    EXPECT_EQ(words[3], 0);
    auto bad = setup(0);
    bad.area = 0x8099;
    EXPECT_EQ(run(h, bad).end_code(), 0x1101);
    bad = setup(0);
    bad.start = 1;
    EXPECT_EQ(run(h, bad).end_code(), 0x1103);
    bad = setup(0);
    bad.count = 0x0200;
    EXPECT_EQ(run(h, bad).end_code(), 0x110C);
}

ProgramAreaFileTransfer program(std::uint16_t mode) {
    return {mode, 0xFFFF, 0, 0xFFFFFFFF, disk_memory_card, file("P.OBJ"), ""};
}

TEST(ProgramAreaFileTransfer, W342_5_3_41_SaveLoadCompareAndNotes) {
    Harness h;
    auto um = h.plc.program().bytes();
    um[0] = 0x11;
    um[5] = 0x22;
    auto r = run(h, program(0));
    ASSERT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(r.data_hex(), "00 00 00 08");  // up to the last used 4-byte unit
    EXPECT_EQ(run(h, program(2)).end_code(), 0x0000);
    // Note 2: no file -> program in RUN or MONITOR.
    EXPECT_EQ(run(h, program(1)).end_code(), 0x2206);
    h.plc.set_mode(OperatingMode::monitor);
    EXPECT_EQ(run(h, program(1)).end_code(), 0x2205);
    h.plc.set_mode(OperatingMode::program);
    // Note 1: under DIP protection program -> file still runs, file -> program does not.
    h.plc.set_dip_write_protection(true);
    EXPECT_EQ(run(h, program(1)).end_code(), 0x2101);
    auto other = program(0);
    other.file = file("Q.OBJ");
    EXPECT_EQ(run(h, other).end_code(), 0x0000);
    h.plc.set_dip_write_protection(false);
    um[5] = 0;
    um[0] = 0x33;
    r = run(h, program(2));
    EXPECT_EQ(r.end_code(), 0x2007);
    EXPECT_EQ(r.data_hex(), "00 00 00 00");
    r = run(h, program(1));
    ASSERT_EQ(r.end_code(), 0x0000);
    EXPECT_EQ(um[0], 0x11);
    EXPECT_EQ(um[5], 0x22);
    auto bad = program(0);
    bad.program_number = 0;
    EXPECT_EQ(run(h, bad).end_code(), 0x1106);
    bad = program(0);
    bad.length = 4;
    EXPECT_EQ(run(h, bad).end_code(), 0x110C);
    h.plc.program().set_prohibit_transfer(true);
    other.file = file("R.OBJ");
    EXPECT_EQ(run(h, other).end_code(), 0x2002);
    h.plc.program().set_prohibit_overwrite(true);
    EXPECT_EQ(run(h, program(1)).end_code(), 0x2102);
}

// Not on this CPU Unit: 22 20 is the CP1H's Memory Cassette command.
TEST(FileMemoryHandlers, W342_5_3_43_MemoryCassetteUndefinedOnCj2h) {
    Harness h;
    EXPECT_EQ(h.send("2220 8003 0000 0000").end_code(), 0x0401);
}

}  // namespace
}  // namespace fins::test
