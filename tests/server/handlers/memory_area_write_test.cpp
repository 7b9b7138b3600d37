// 01 02 MEMORY AREA WRITE through full request frames (W342 5-3-3, 5-2-2).
#include <gtest/gtest.h>

#include <functional>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

using plc::IoMemory;

struct WriteCase {
    const char* area;
    const char* parameters;  // after 01 02: address, count, data
    std::function<bool(const IoMemory&)> written;
};

std::uint16_t word(const IoMemory& m, Region r, std::size_t i, std::uint8_t bank = 0) {
    return m.words(r, bank)[i];
}

// Every code of the 5-3-3 area table (CS/CJ then CV).
const std::vector<WriteCase>& write_cases() {
    static const std::vector<WriteCase> cases = {
        {"CIO bit", "30 000A 0F 0002 01 01",
         [](const IoMemory& m) {
             return word(m, Region::cio, 10) == 0x8000 && word(m, Region::cio, 11) == 1;
         }},
        {"WR bit", "31 01FF 0F 0001 01",
         [](const IoMemory& m) { return word(m, Region::work, 511) == 0x8000; }},
        {"HR bit", "32 0000 00 0001 01",
         [](const IoMemory& m) { return word(m, Region::holding, 0) == 1; }},
        {"AR bit", "33 01C0 03 0001 01",
         [](const IoMemory& m) { return word(m, Region::auxiliary, 448) == 8; }},
        {"CIO word", "B0 17FF 00 0001 1234",
         [](const IoMemory& m) { return word(m, Region::cio, 6143) == 0x1234; }},
        {"WR word", "B1 0001 00 0001 ABCD",
         [](const IoMemory& m) { return word(m, Region::work, 1) == 0xABCD; }},
        {"HR word", "B2 01FF 00 0001 0102",
         [](const IoMemory& m) { return word(m, Region::holding, 511) == 0x0102; }},
        {"AR word", "B3 03BF 00 0001 0959",
         [](const IoMemory& m) { return word(m, Region::auxiliary, 959) == 0x0959; }},
        {"timer PV", "89 0FFF 00 0001 0999",
         [](const IoMemory& m) { return word(m, Region::timer_counter, 4095) == 0x0999; }},
        {"counter PV", "89 8000 00 0002 0001 0002",
         [](const IoMemory& m) {
             return word(m, Region::timer_counter, plc::counter_base + 1) == 2;
         }},
        {"DM bit", "02 0000 08 0001 01",
         [](const IoMemory& m) { return word(m, Region::dm, 0) == 0x0100; }},
        {"DM word", "82 7FFF 00 0001 7FFF",
         [](const IoMemory& m) { return word(m, Region::dm, 32767) == 0x7FFF; }},
        {"EM current bank bit", "0A 0001 00 0001 01",
         [](const IoMemory& m) { return word(m, Region::em, 1) == 1; }},
        {"EM current bank word", "98 0002 00 0001 9898",
         [](const IoMemory& m) { return word(m, Region::em, 2) == 0x9898; }},
        {"IR", "DC 0100 00 0002 11223344 55667788",
         [](const IoMemory& m) { return m.index_registers()[1] == 0x55667788U; }},
        {"DR", "BC 020F 00 0001 0DDD",
         [](const IoMemory& m) { return word(m, Region::data_register, 15) == 0x0DDD; }},
        {"CV CIO word", "80 09FB 00 0001 2555",
         [](const IoMemory& m) { return word(m, Region::cio, 2555) == 0x2555; }},
        {"CV AR word", "80 0EBF 00 0001 0959",
         [](const IoMemory& m) { return word(m, Region::auxiliary, 959) == 0x0959; }},
        {"CV timer PV", "81 07FF 00 0001 2047",
         [](const IoMemory& m) { return word(m, Region::timer_counter, 2047) == 0x2047; }},
        {"CV counter PV", "81 0FFF 00 0001 2047",
         [](const IoMemory& m) {
             return word(m, Region::timer_counter, plc::counter_base + 2047) == 0x2047;
         }},
        {"CV EM bank 0 word", "90 0000 00 0001 9090",
         [](const IoMemory& m) { return word(m, Region::em, 0, 0) == 0x9090; }},
        {"CV DR", "9C 0003 00 0001 0D00",
         [](const IoMemory& m) { return word(m, Region::data_register, 0) == 0x0D00; }},
    };
    return cases;
}

TEST(MemoryAreaWrite, W342_5_3_3_EveryWritableAreaThroughAFrame) {
    for (const auto& c : write_cases()) {
        SCOPED_TRACE(c.area);
        Harness h;
        const auto reply = h.send(std::string("0102 ") + c.parameters);
        EXPECT_EQ(reply.end_code(), 0x0000);
        EXPECT_TRUE(reply.data().empty());
        EXPECT_TRUE(c.written(h.memory()));
    }
}

TEST(MemoryAreaWrite, W342_5_3_3_WriteThenReadBackEveryEmBank) {
    Harness h;
    for (std::uint8_t bank = 0; bank < 0x19; ++bank) {
        SCOPED_TRACE(int{bank});
        const auto word_code =
            static_cast<std::uint8_t>(bank < 0x10 ? 0xA0 + bank : 0x60 + bank - 0x10);
        const auto bit_code =
            static_cast<std::uint8_t>(bank < 0x10 ? 0x20 + bank : 0xE0 + bank - 0x10);
        const std::string w = to_hex(std::vector<std::uint8_t>{word_code});
        const std::string b = to_hex(std::vector<std::uint8_t>{bit_code});
        const std::string value = to_hex(std::vector<std::uint8_t>{0x40, bank});
        EXPECT_EQ(h.send("0102" + w + "7FFF00 0001" + value).end_code(), 0x0000);
        EXPECT_EQ(h.send("0102" + b + "7FFF0F 0001 01").end_code(), 0x0000);
        EXPECT_EQ(h.memory().words(Region::em, bank)[32767], 0xC000 | bank);
        EXPECT_EQ(h.send("0101" + w + "7FFF00 0001").data(),
                  (std::vector<std::uint8_t>{0xC0, bank}));
        if (bank < 0x10) {
            const std::string cj2 =
                to_hex(std::vector<std::uint8_t>{static_cast<std::uint8_t>(0x50 + bank)});
            EXPECT_EQ(h.send("0102" + cj2 + "000100 0001 5555").end_code(), 0x0000);
            EXPECT_EQ(h.memory().words(Region::em, bank)[1], 0x5555);
        }
    }
}

TEST(MemoryAreaWrite, W342_5_3_3_CountZeroWritesNothing) {
    Harness h;
    const auto reply = h.send("0102 82000000 0000");
    EXPECT_EQ(reply.end_code(), 0x0000);
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0);
}

// Choice: count 0 with data bytes is an elements/data mismatch.
TEST(MemoryAreaWrite, W342_5_1_3_CountZeroWithDataIs1003) {
    Harness h;
    EXPECT_EQ(h.send("0102 82000000 0000 1234").end_code(), 0x1003);
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0);
}

TEST(MemoryAreaWrite, W342_5_1_3_DataLengthNotCountTimesElementSizeIs1003) {
    Harness h;
    EXPECT_EQ(h.send("0102 82000000 0002 1234").end_code(), 0x1003);
    EXPECT_EQ(h.send("0102 82000000 0001 123456").end_code(), 0x1003);
    EXPECT_EQ(h.send("0102 30000000 0002 01").end_code(), 0x1003);
    EXPECT_EQ(h.send("0102 DC010000 0001 1234").end_code(), 0x1003);
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0);
}

// Choice: address errors (1101/1103/1104/2101) are reported before the data length.
TEST(MemoryAreaWrite, W342_5_1_3_AddressErrorsComeBefore1003) {
    Harness h;
    EXPECT_EQ(h.send("0102 FF000000 0001 12").end_code(), 0x1101);
    EXPECT_EQ(h.send("0102 82800000 0001 12").end_code(), 0x1103);
    EXPECT_EQ(h.send("0102 827FFF00 0002 12").end_code(), 0x1104);
    EXPECT_EQ(h.send("0102 B3000000 0001 12").end_code(), 0x2101);
}

TEST(MemoryAreaWrite, W342_5_2_2_A000ToA447AreReadOnly2101) {
    Harness h;
    EXPECT_EQ(h.send("0102 B3000000 0001 FFFF").end_code(), 0x2101);
    EXPECT_EQ(h.send("0102 B301BF00 0002 FFFF FFFF").end_code(), 0x2101);  // A447-A448
    EXPECT_EQ(h.send("0102 3301BF0F 0001 01").end_code(), 0x2101);
    EXPECT_EQ(h.send("0102 800B0000 0001 FFFF").end_code(), 0x2101);  // CV A000
    EXPECT_EQ(h.memory().words(Region::auxiliary)[447], 0);
    EXPECT_EQ(h.memory().words(Region::auxiliary)[448], 0);
    EXPECT_EQ(h.send("0102 B301C000 0001 FFFF").end_code(), 0x0000);
}

TEST(MemoryAreaWrite, W342_5_3_3_CodesTheTableDoesNotListAre1101) {
    Harness h;
    // Completion flags, task flags/status, area 07, EM bank number, forced status,
    // CV bit code 00.
    for (const char* p :
         {"09000000 0001 01", "06000000 0001 01", "46000000 0001 01", "07100F00 0001 00",
          "BC0F0000 0001 0001", "70000000 0001 01", "F0000000 0001 00000000", "49000000 0001 01",
          "00000000 0001 01", "FF000000 0001 01"})
        EXPECT_EQ(h.send(std::string("0102 ") + p).end_code(), 0x1101) << p;
}

TEST(MemoryAreaWrite, W342_5_1_3_StartAndEndRangeErrors) {
    Harness h;
    EXPECT_EQ(h.send("0102 B0180000 0001 0000").end_code(), 0x1103);
    EXPECT_EQ(h.send("0102 30000010 0001 01").end_code(), 0x1103);
    EXPECT_EQ(h.send("0102 B0000001 0001 0000").end_code(), 0x1103);
    EXPECT_EQ(h.send("0102 B017FF00 0002 0000 0000").end_code(), 0x1104);
    EXPECT_EQ(h.send("0102 BC020F00 0002 0000 0000").end_code(), 0x1104);
}

TEST(MemoryAreaWrite, W342_5_1_3_EmBankTheModelLacksIs1101) {
    plc::Profile p = plc::cj2h();
    p.em_banks = 2;
    Harness h(p);
    EXPECT_EQ(h.send("0102 A1000000 0001 1111").end_code(), 0x0000);
    EXPECT_EQ(h.send("0102 A2000000 0001 1111").end_code(), 0x1101);
    EXPECT_EQ(h.send("0102 22000000 0001 01").end_code(), 0x1101);
    EXPECT_EQ(h.send("0102 92000000 0001 1111").end_code(), 0x1101);
}

TEST(MemoryAreaWrite, W342_5_3_3_PvWriteLeavesCompletionFlagsOn) {
    Harness h;
    h.memory().set_completion_flag(3, true);
    h.memory().set_completion_flag(plc::counter_base + 3, true);
    EXPECT_EQ(h.send("0102 89000300 0001 0000").end_code(), 0x0000);
    EXPECT_EQ(h.send("0102 89800300 0001 0000").end_code(), 0x0000);
    EXPECT_TRUE(h.memory().completion_flag(3));
    EXPECT_TRUE(h.memory().completion_flag(plc::counter_base + 3));
}

TEST(MemoryAreaWrite, W342_5_3_44_WritesKeepForcedBits) {
    Harness h;
    ASSERT_TRUE(h.memory().force_bit(Region::cio, 0, 0, true));
    ASSERT_TRUE(h.memory().force_bit(Region::holding, 2, 1, false));
    EXPECT_EQ(h.send("0102 B0000000 0001 0000").end_code(), 0x0000);
    EXPECT_EQ(h.send("0102 32000201 0001 01").end_code(), 0x0000);
    EXPECT_EQ(h.send("0102 B2000200 0001 FFFF").end_code(), 0x0000);
    EXPECT_EQ(h.memory().words(Region::cio)[0], 0x0001);
    EXPECT_EQ(h.memory().words(Region::holding)[2], 0xFFFD);
    EXPECT_EQ(h.send("0104 70000000 F2000200").data_hex(), "70 03 F2 00 02 FF FD");
}

TEST(MemoryAreaWrite, W342_5_1_3_ShortCommandIs1002) {
    Harness h;
    EXPECT_EQ(h.send("0102").end_code(), 0x1002);
    EXPECT_EQ(h.send("0102 82000000 00").end_code(), 0x1002);
}

}  // namespace
}  // namespace fins::test
