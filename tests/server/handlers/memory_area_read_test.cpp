// 01 01 MEMORY AREA READ through full request frames (W342 5-3-2, 5-2-2).
#include <gtest/gtest.h>

#include <chrono>
#include <functional>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

using plc::IoMemory;

struct ReadCase {
    const char* area;
    const char* parameters;  // after 01 01
    std::function<void(IoMemory&)> setup;
    const char* data;
};

// One case per area and access type of the 5-2-2 table (CS/CJ then CV codes).
const std::vector<ReadCase>& read_cases() {
    static const std::vector<ReadCase> cases = {
        {"CIO bit", "30 000A 0D 0002", [](IoMemory& m) { m.words(Region::cio)[10] = 0x2000; },
         "01 00"},
        {"CIO word", "B0 17FF 00 0001", [](IoMemory& m) { m.words(Region::cio)[6143] = 0x1234; },
         "12 34"},
        {"WR bit", "31 01FF 0F 0001", [](IoMemory& m) { m.words(Region::work)[511] = 0x8000; },
         "01"},
        {"WR word", "B1 0005 00 0001", [](IoMemory& m) { m.words(Region::work)[5] = 0x0505; },
         "05 05"},
        {"HR bit", "32 0001 00 0001", [](IoMemory& m) { m.words(Region::holding)[1] = 0x0001; },
         "01"},
        {"HR word", "B2 01FF 00 0001", [](IoMemory& m) { m.words(Region::holding)[511] = 0xBEEF; },
         "BE EF"},
        {"AR bit", "33 0000 01 0001", [](IoMemory& m) { m.words(Region::auxiliary)[0] = 0x0002; },
         "01"},
        {"AR word", "B3 03BF 00 0001",
         [](IoMemory& m) { m.words(Region::auxiliary)[959] = 0x0959; }, "09 59"},
        {"timer completion flag", "09 000A 00 0002",
         [](IoMemory& m) { m.set_completion_flag(11, true); }, "00 01"},
        {"counter completion flag", "09 8FFF 00 0001",
         [](IoMemory& m) { m.set_completion_flag(plc::counter_base + 4095, true); }, "01"},
        {"timer PV", "89 0005 00 0001",
         [](IoMemory& m) { m.words(Region::timer_counter)[5] = 0x0100; }, "01 00"},
        {"counter PV", "89 8005 00 0001",
         [](IoMemory& m) { m.words(Region::timer_counter)[plc::counter_base + 5] = 0x0200; },
         "02 00"},
        {"DM bit", "02 7FFF 0F 0001", [](IoMemory& m) { m.words(Region::dm)[32767] = 0x8000; },
         "01"},
        {"DM word", "82 000A 00 0002", [](IoMemory& m) { m.words(Region::dm)[11] = 0x0B0B; },
         "00 00 0B 0B"},
        {"EM current bank bit", "0A 0003 04 0001",
         [](IoMemory& m) {
             m.set_current_em_bank(2);
             m.words(Region::em, 2)[3] = 0x0010;
         },
         "01"},
        {"EM current bank word", "98 7FFF 00 0001",
         [](IoMemory& m) {
             m.set_current_em_bank(0x18);
             m.words(Region::em, 0x18)[32767] = 0x1818;
         },
         "18 18"},
        {"EM current bank number", "BC 0F00 00 0001", [](IoMemory& m) { m.set_current_em_bank(7); },
         "00 07"},
        {"task flag", "06 001F 00 0001", [](IoMemory& m) { m.set_task_flag(31, true); }, "01"},
        {"task status", "46 0000 00 0002", [](IoMemory& m) { m.set_task_status(1, 0x03); },
         "00 03"},
        {"IR", "DC 010F 00 0001", [](IoMemory& m) { m.index_registers()[15] = 0x00012345; },
         "00 01 23 45"},
        {"DR", "BC 0200 00 0002", [](IoMemory& m) { m.words(Region::data_register)[1] = 0xFFFF; },
         "00 00 FF FF"},
        {"clock pulses", "07 0000 00 0005", [](IoMemory&) {}, "01 01 01 01 01"},  // at the epoch
        {"condition flags", "07 100E 00 0002", [](IoMemory&) {}, "00 01"},
        {"access error flag", "07 2001 00 0001", [](IoMemory& m) { m.set_access_error_flag(true); },
         "01"},
        // CV mode codes.
        {"CV CIO bit", "00 09FB 0F 0001", [](IoMemory& m) { m.words(Region::cio)[2555] = 0x8000; },
         "01"},
        {"CV AR bit", "00 0B0A 00 0001",
         [](IoMemory& m) { m.words(Region::auxiliary)[10] = 0x0001; }, "01"},
        {"CV CIO word", "80 0010 00 0001", [](IoMemory& m) { m.words(Region::cio)[16] = 0xC10C; },
         "C1 0C"},
        {"CV AR word", "80 0CC0 00 0001",
         [](IoMemory& m) { m.words(Region::auxiliary)[448] = 0x0448; }, "04 48"},
        {"CV timer completion flag", "01 07FF 00 0001",
         [](IoMemory& m) { m.set_completion_flag(2047, true); }, "01"},
        {"CV counter completion flag", "01 0800 00 0001",
         [](IoMemory& m) { m.set_completion_flag(plc::counter_base, true); }, "01"},
        {"CV timer PV", "81 0001 00 0001",
         [](IoMemory& m) { m.words(Region::timer_counter)[1] = 0x0011; }, "00 11"},
        {"CV counter PV", "81 0801 00 0001",
         [](IoMemory& m) { m.words(Region::timer_counter)[plc::counter_base + 1] = 0x0C01; },
         "0C 01"},
        {"CV EM bank 7 word", "97 0001 00 0001",
         [](IoMemory& m) { m.words(Region::em, 7)[1] = 0x0701; }, "07 01"},
        {"CV DR", "9C 0005 00 0001",
         [](IoMemory& m) { m.words(Region::data_register)[2] = 0x0D02; }, "0D 02"},
        {"CV EM current bank number", "9C 0006 00 0001",
         [](IoMemory& m) { m.set_current_em_bank(3); }, "00 03"},
    };
    return cases;
}

TEST(MemoryAreaRead, W342_5_2_2_EveryAreaReadsThroughAFrame) {
    for (const auto& c : read_cases()) {
        SCOPED_TRACE(c.area);
        Harness h;
        c.setup(h.memory());
        const auto reply = h.send(std::string("0101 ") + c.parameters);
        EXPECT_EQ(reply.end_code(), 0x0000);
        EXPECT_EQ(reply.data_hex(), to_hex(hex(c.data)));
    }
}

TEST(MemoryAreaRead, W342_5_2_2_EveryEmBankByWordAndBitCode) {
    Harness h;
    for (std::uint8_t bank = 0; bank < 0x19; ++bank) {
        SCOPED_TRACE(int{bank});
        h.memory().words(Region::em, bank)[100] = static_cast<std::uint16_t>(0x8000 | bank);
        const auto word_code =
            static_cast<std::uint8_t>(bank < 0x10 ? 0xA0 + bank : 0x60 + bank - 0x10);
        const auto bit_code =
            static_cast<std::uint8_t>(bank < 0x10 ? 0x20 + bank : 0xE0 + bank - 0x10);
        const auto word =
            h.send("0101" + to_hex(std::vector<std::uint8_t>{word_code}) + "006400 0001");
        EXPECT_EQ(word.end_code(), 0x0000);
        EXPECT_EQ(word.data(), (std::vector<std::uint8_t>{0x80, bank}));
        const auto bit =
            h.send("0101" + to_hex(std::vector<std::uint8_t>{bit_code}) + "00640F 0001");
        EXPECT_EQ(bit.data(), (std::vector<std::uint8_t>{0x01}));
        if (bank < 0x10) {  // W342 5-2-2 note 2: CJ2 codes 50-5F
            const auto cj2 = h.send(
                "0101" + to_hex(std::vector<std::uint8_t>{static_cast<std::uint8_t>(0x50 + bank)}) +
                "006400 0001");
            EXPECT_EQ(cj2.data(), (std::vector<std::uint8_t>{0x80, bank}));
        }
    }
}

TEST(MemoryAreaRead, Style_ManualExampleReadsTenWordsFromD10) {
    Harness h;
    for (std::uint16_t i = 0; i < 10; ++i)
        h.memory().words(Region::dm)[10 + i] = i;
    const auto reply = h.send("0101 82000A00 000A");
    EXPECT_EQ(reply.end_code(), 0x0000);
    EXPECT_EQ(reply.data_hex(), to_hex(hex("0000 0001 0002 0003 0004 0005 0006 0007 0008 0009")));
}

TEST(MemoryAreaRead, W342_5_3_2_ClockPulsesFollowTheRequestTime) {
    Harness h;
    h.context.now = plc::TimePoint{} + std::chrono::milliseconds(750);
    EXPECT_EQ(h.send("0101 07000100 0001").data_hex(), "00");
    h.context.now = plc::TimePoint{} + std::chrono::milliseconds(1250);
    EXPECT_EQ(h.send("0101 07000100 0001").data_hex(), "01");
}

TEST(MemoryAreaRead, W342_5_3_2_Note1_CountZeroIsNormalWithNoData) {
    Harness h;
    const auto reply = h.send("0101 82000000 0000");
    EXPECT_EQ(reply.end_code(), 0x0000);
    EXPECT_TRUE(reply.data().empty());
    EXPECT_EQ(h.send("0101 B0 17FF 00 0000").end_code(), 0x0000);
}

// Choice: with count 0 the area code and start address are still validated.
TEST(MemoryAreaRead, W342_5_3_2_Note1_CountZeroStillChecksTheStart) {
    Harness h;
    EXPECT_EQ(h.send("0101 FF000000 0000").end_code(), 0x1101);
    EXPECT_EQ(h.send("0101 82800000 0000").end_code(), 0x1103);
}

TEST(MemoryAreaRead, W342_5_1_3_UnknownAreaCodeIs1101) {
    Harness h;
    for (const char* p : {"FF000000 0001", "03000000 0001", "99000000 0001"})
        EXPECT_EQ(h.send(std::string("0101 ") + p).end_code(), 0x1101) << p;
}

TEST(MemoryAreaRead, W342_5_3_2_ForcedStatusCodesAreNotListedSo1101) {
    Harness h;
    for (const char* p : {"70000000 0001", "71000000 0001", "72000000 0001", "F0000000 0001",
                          "F1000000 0001", "F2000000 0001", "49000000 0001"})
        EXPECT_EQ(h.send(std::string("0101 ") + p).end_code(), 0x1101) << p;
}

TEST(MemoryAreaRead, W342_5_1_3_StartOutsideTheAreaIs1103) {
    Harness h;
    EXPECT_EQ(h.send("0101 B0180000 0001").end_code(), 0x1103);  // CIO 6144
    EXPECT_EQ(h.send("0101 B1020000 0001").end_code(), 0x1103);  // W512
    EXPECT_EQ(h.send("0101 B303C000 0001").end_code(), 0x1103);  // A960
    EXPECT_EQ(h.send("0101 89100000 0001").end_code(), 0x1103);  // between T and C
    EXPECT_EQ(h.send("0101 DC011000 0001").end_code(), 0x1103);  // IR16
}

TEST(MemoryAreaRead, W342_5_2_1_BitAbove0FOrBitOnWordAccessIs1103) {
    Harness h;
    EXPECT_EQ(h.send("0101 30000A10 0001").end_code(), 0x1103);
    EXPECT_EQ(h.send("0101 02000AFF 0001").end_code(), 0x1103);
    EXPECT_EQ(h.send("0101 82000A01 0001").end_code(), 0x1103);
    EXPECT_EQ(h.send("0101 09000A01 0001").end_code(), 0x1103);  // completion flags: bit 00
}

TEST(MemoryAreaRead, W342_5_1_3_EndPastTheAreaIs1104) {
    Harness h;
    EXPECT_EQ(h.send("0101 827FFF00 0002").end_code(), 0x1104);
    EXPECT_EQ(h.send("0101 3017FF0F 0002").end_code(), 0x1104);
    EXPECT_EQ(h.send("0101 890FFF00 0002").end_code(), 0x1104);
    EXPECT_EQ(h.send("0101 DC010F00 0002").end_code(), 0x1104);
    EXPECT_EQ(h.send("0101 07000400 0002").end_code(), 0x1104);
}

TEST(MemoryAreaRead, W342_5_2_2_NumberOfElements999WordsIsTheLimit) {
    Harness h;
    const auto ok = h.send("0101 82000000 03E7");
    EXPECT_EQ(ok.end_code(), 0x0000);
    EXPECT_EQ(ok.data().size(), 1998U);
    EXPECT_EQ(ok.frame.size(), max_frame_size);
    EXPECT_EQ(h.send("0101 82000000 03E8").end_code(), 0x110B);
    EXPECT_EQ(h.send("0101 02000000 07CE").end_code(), 0x0000);  // 1,998 bits
    EXPECT_EQ(h.send("0101 02000000 07CF").end_code(), 0x110B);
}

// Choice: address errors are reported before the response-length error.
TEST(MemoryAreaRead, W342_5_1_3_AddressErrorsComeBefore110B) {
    Harness h;
    EXPECT_EQ(h.send("0101 827FFF00 03E8").end_code(), 0x1104);
    EXPECT_EQ(h.send("0101 82800000 FFFF").end_code(), 0x1103);
}

TEST(MemoryAreaRead, W342_5_1_3_ShortCommandIs1002LongIs1001) {
    Harness h;
    EXPECT_EQ(h.send("0101").end_code(), 0x1002);
    EXPECT_EQ(h.send("0101 82000000 00").end_code(), 0x1002);
    EXPECT_EQ(h.send("0101 82000000 0001 00").end_code(), 0x1001);
    EXPECT_TRUE(h.send("0101 82000000 0001 00").data().empty());
}

TEST(MemoryAreaRead, W342_5_1_3_EmBankTheModelLacksIs1101) {
    plc::Profile p = plc::cj2h();
    p.em_banks = 4;
    Harness h(p);
    EXPECT_EQ(h.send("0101 A3000000 0001").end_code(), 0x0000);
    EXPECT_EQ(h.send("0101 A4000000 0001").end_code(), 0x1101);
    EXPECT_EQ(h.send("0101 E0000000 0001").end_code(), 0x1101);
}

}  // namespace
}  // namespace fins::test
