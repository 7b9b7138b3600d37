// The profile registry: every model's sizes, the area codes it accepts and the
// commands it answers (README (profiles and configuration) is the table these tests pin).
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "plc/io_memory_test_util.hpp"
#include "plc/profile.hpp"

namespace fins::plc::test {
namespace {

const Profile& get(std::string_view name) {
    const Profile* p = find_profile(name);
    EXPECT_NE(p, nullptr) << name;
    static const Profile fallback = cj2h();
    return p != nullptr ? *p : fallback;
}

std::uint16_t read_code(const IoMemory& m, std::uint8_t code, std::uint16_t word,
                        std::uint8_t bit = 0, std::uint32_t count = 1) {
    return code_of(m.locate(at(code, word, bit), count, use_multi_read, Intent::read));
}

TEST(Profiles, RegistryHoldsSixUniqueProfilesWithCj2hFirst) {
    const auto all = profiles();
    ASSERT_EQ(all.size(), 6u);
    EXPECT_EQ(all.front().name, "cj2h");
    std::set<std::string> names;
    for (const auto& p : all) {
        EXPECT_TRUE(names.insert(p.name).second) << p.name;
        EXPECT_LE(p.model.size(), 20u) << p.name;  // 05 01: 20 ASCII characters
        EXPECT_LE(p.units.size(), 16u + 1u) << p.name;
        for (std::size_t i = 1; i < p.units.size(); ++i)
            EXPECT_LT(p.units[i - 1].unit_address, p.units[i].unit_address) << p.name;
    }
    EXPECT_EQ(cj2h().name, "cj2h");
    EXPECT_EQ(Profile{}.model, cj2h().model);
}

// Names and models match ignoring case, '-' and '_' being the same: the catalogue
// spelling ("CJ1M-CPU13") finds the model as the unit answers it ("CJ1M_CPU13").
TEST(Profiles, NamesAndModelsMatchIgnoringCase) {
    const std::pair<const char*, const char*> cases[] = {
        {"cj2h", "cj2h"},           {"CJ2H", "cj2h"},         {"CJ2H-CPU68-EIP", "cj2h"},
        {"cj2h-cpu68-eip", "cj2h"}, {"cs1h", "cs1h"},         {"CS1H-CPU67H", "cs1h"},
        {"cs1h-lcb", "cs1h-lcb"},   {"CS1H-LCB", "cs1h-lcb"}, {"cj1m", "cj1m"},
        {"CJ1M-CPU13", "cj1m"},     {"cp1h", "cp1h"},         {"CP1H-XA40DR-A", "cp1h"},
        {"nx102", "nx102"},         {"NX102-9000", "nx102"},
    };
    for (const auto& [given, expected] : cases) {
        const Profile* p = find_profile(given);
        ASSERT_NE(p, nullptr) << given;
        EXPECT_EQ(p->name, expected) << given;
    }
    for (const char* unknown : {"", "cj2", "cj2h ", "CJ2H-CPU68", "nx1p2", "cs1h-lcb-x"})
        EXPECT_EQ(find_profile(unknown), nullptr) << unknown;
}

struct Sizes {
    const char* name;
    const char* model;
    std::uint8_t em_banks;
    std::uint16_t program_kwords;
    std::uint32_t holding, auxiliary, timers, counters;
    bool cj2_codes, cv_codes, cpu_areas, loop_control, nx;
};

TEST(Profiles, SizesAndOptionsOfEveryProfile) {
    const Sizes table[] = {
        // Program area = twice the catalogue K steps (profile.cpp [SCAN]): CJ2H-CPU68-EIP
        // 400K steps, CS1H-CPU67H 250K, CJ1M-CPU13 and CP1H-XA40DR-A 20K [LF].
        {"cj2h", "CJ2H-CPU68-EIP", 25, 800, 512, 960, 4096, 4096, true, true, true, false, false},
        {"cs1h", "CS1H_CPU67H", 13, 500, 512, 960, 4096, 4096, false, true, true, false, false},
        {"cs1h-lcb", "CS1H_CPU67H", 13, 500, 512, 960, 4096, 4096, false, true, true, true, false},
        {"cj1m", "CJ1M_CPU13", 0, 40, 512, 960, 4096, 4096, false, true, true, false, false},
        {"cp1h", "CP1H_XA40DR-A", 0, 40, 512, 960, 4096, 4096, false, false, true, false, false},
        {"nx102", "NX102-9000", 4, 0x14, 512, 0, 0, 0, false, false, false, false, true},
    };
    for (const auto& s : table) {
        const Profile& p = get(s.name);
        SCOPED_TRACE(s.name);
        EXPECT_EQ(p.model, s.model);
        EXPECT_EQ(p.em_banks, s.em_banks);
        EXPECT_EQ(p.em_bank_words, 32768u);
        EXPECT_EQ(p.program_kwords, s.program_kwords);
        EXPECT_EQ(p.cio_words, 6144u);
        EXPECT_EQ(p.work_words, 512u);
        EXPECT_EQ(p.holding_words, s.holding);
        EXPECT_EQ(p.auxiliary_words, s.auxiliary);
        EXPECT_EQ(p.timers, s.timers);
        EXPECT_EQ(p.counters, s.counters);
        EXPECT_EQ(p.dm_words, 32768u);
        EXPECT_EQ(p.cj2_em_codes, s.cj2_codes);
        EXPECT_EQ(p.cv_mode_codes, s.cv_codes);
        EXPECT_EQ(p.cpu_areas, s.cpu_areas);
        EXPECT_EQ(p.loop_control, s.loop_control);
        EXPECT_EQ(p.nx_fixed_values, s.nx);
        EXPECT_EQ(p.commands.empty(), !s.nx);
    }
}

TEST(Profiles, MountedUnits) {
    EXPECT_EQ(get("cj2h").units.size(), 1u);
    EXPECT_EQ(get("cj2h").units[0].unit_address, 0x10);
    EXPECT_EQ(get("cj2h").units[0].model, "CJ2B-EIP21");
    EXPECT_EQ(get("cs1h").units[0].model, "CS1W-ETN21");
    ASSERT_EQ(get("cs1h-lcb").units.size(), 2u);
    EXPECT_EQ(get("cs1h-lcb").units[1].unit_address, 0xE1);  // Inner Board
    EXPECT_EQ(get("cs1h-lcb").units[1].model, "CS1W-LCB05");
    EXPECT_EQ(get("cj1m").units[0].model, "CJ1W-ETN21");
    EXPECT_EQ(get("cp1h").units[0].model, "CJ1W-ETN21");
    EXPECT_TRUE(get("nx102").units.empty());
    EXPECT_FALSE(get("nx102").battery);
    EXPECT_EQ(get("cj1m").memory_card_type, 0x00);
    EXPECT_EQ(get("cs1h").memory_card_kbytes, 30720);
    EXPECT_EQ(get("cj2h").unit(0x10), &get("cj2h").units[0]);
    EXPECT_EQ(get("cj2h").unit(0x11), nullptr);
}

// W342 5-3-15: no memory card = type 00 and size 0000; a card = its type and size. Every
// CS/CJ/CP profile agrees with itself (NX keeps W596 2-2's fixed type 04).
TEST(Profiles, W342_5_3_15_MemoryCardTypeAndSizeAgree) {
    for (const auto& p : profiles()) {
        if (p.nx_fixed_values) continue;
        SCOPED_TRACE(p.name);
        EXPECT_EQ(p.memory_card_type == 0x00, p.memory_card_kbytes == 0);
        EXPECT_EQ(p.has_memory_card(), p.memory_card_kbytes != 0);
    }
    EXPECT_TRUE(get("cj2h").has_memory_card());  // issue 8: inserted, so 22 xx works
    EXPECT_TRUE(get("cs1h").has_memory_card());
    EXPECT_FALSE(get("cp1h").has_memory_card());  // a Memory Cassette, not a card
}

// Model strings as the units answer 05 01 (profile.cpp [LF], [SCAN]): CS1/CJ1/CP1 with
// an underscore, CJ2 with hyphens; CJ2 unit versions 1.x.
TEST(Profiles, ModelStringsAndVersionsAsRealUnitsAnswer) {
    EXPECT_EQ(get("cj2h").model, "CJ2H-CPU68-EIP");
    EXPECT_EQ(get("cj2h").system_version, "01.90");
    EXPECT_EQ(get("cs1h").model, "CS1H_CPU67H");
    EXPECT_EQ(get("cj1m").model, "CJ1M_CPU13");
    EXPECT_EQ(get("cj1m").system_version, "04.10");
    EXPECT_EQ(get("cp1h").model, "CP1H_XA40DR-A");
}

// W596 2-2: exactly 0101-0105, 0501, 0601, 0701, 0702 on an NX CPU Unit.
TEST(Profiles, W596_2_2_Nx102AnswersExactlyTheFinsSubset) {
    const Profile& nx = get("nx102");
    const std::set<unsigned> subset{0x0101, 0x0102, 0x0103, 0x0104, 0x0105,
                                    0x0501, 0x0601, 0x0701, 0x0702};
    unsigned supported = 0;
    for (unsigned code = 0; code <= 0xFFFF; ++code) {
        const CommandCode c{static_cast<std::uint8_t>(code >> 8), static_cast<std::uint8_t>(code)};
        const bool yes = nx.supports(c);
        EXPECT_EQ(yes, subset.count(code) == 1) << std::hex << code;
        supported += yes ? 1U : 0U;
    }
    EXPECT_EQ(supported, 9u);
    for (const auto& p : profiles())
        if (!p.nx_fixed_values) {
            EXPECT_TRUE(p.supports(CommandCode{0x02, 0x01})) << p.name;
            EXPECT_TRUE(p.supports(CommandCode{0x23, 0x01})) << p.name;
        }
}

TEST(Profiles, W342_5_2_2_EmBankLimitsPerProfile) {
    for (const char* name : {"cj2h", "cs1h", "cj1m", "cp1h", "nx102"}) {
        const Profile& p = get(name);
        HeapMemory m(p);
        SCOPED_TRACE(name);
        for (unsigned bank = 0; bank < 0x19; ++bank) {
            const auto code =
                static_cast<std::uint8_t>(bank < 0x10 ? 0xA0 + bank : 0x60 + bank - 0x10);
            EXPECT_EQ(read_code(m, code, 0x7FFF), bank < p.em_banks ? 0 : 0x1101) << bank;
            EXPECT_EQ(m.words(Region::em, static_cast<std::uint8_t>(bank)).size(),
                      bank < p.em_banks ? 32768u : 0u);
        }
        // EM current bank (98) and its number (BC 0F00) need EM and the CPU's own areas.
        const bool current = p.em_banks != 0 && p.cpu_areas;
        EXPECT_EQ(read_code(m, 0x98, 0), current ? 0 : 0x1101);
        EXPECT_EQ(read_code(m, 0xBC, 0x0F00), current ? 0 : 0x1101);
    }
}

TEST(Profiles, W342_5_2_2_Note2_Cj2CodesOnlyOnCj2h) {
    for (const auto& p : profiles()) {
        HeapMemory m(p);
        const bool expected = p.name == "cj2h";
        EXPECT_EQ(read_code(m, 0x50, 0), expected ? 0 : 0x1101) << p.name;
        EXPECT_EQ(read_code(m, 0x5F, 0), expected ? 0 : 0x1101) << p.name;
    }
}

// Choice: CS/CJ accept the CV-mode codes; CP1H and NX102 do not.
TEST(Profiles, CvModeCodesOnCsCjOnly) {
    for (const auto& p : profiles()) {
        HeapMemory m(p);
        const std::uint16_t expected = p.cv_mode_codes ? 0 : 0x1101;
        EXPECT_EQ(read_code(m, 0x80, 0x0010), expected) << p.name;     // CV CIO word
        EXPECT_EQ(read_code(m, 0x81, 0x0800), expected) << p.name;     // CV counter PV
        EXPECT_EQ(read_code(m, 0x80, 0x0CC0), expected) << p.name;     // CV A448
        EXPECT_EQ(read_code(m, 0x00, 0x0000, 3), expected) << p.name;  // CV CIO bit
    }
    EXPECT_FALSE(get("cp1h").cv_mode_codes);
    EXPECT_TRUE(get("cj1m").cv_mode_codes);
}

// W596 2-2: only CIO, WR, HR, DM and EM exist on an NX CPU Unit; everything else is 1101.
TEST(Profiles, W596_2_2_Nx102HasOnlyCjCompatibleAreas) {
    HeapMemory m(get("nx102"));
    const std::uint8_t present[] = {0xB0, 0xB1, 0xB2, 0x82, 0xA0, 0xA3,
                                    0x30, 0x31, 0x32, 0x02, 0x20};
    for (std::uint8_t code : present)
        EXPECT_EQ(read_code(m, code, 0), 0) << std::hex << unsigned{code};
    EXPECT_EQ(read_code(m, 0xB2, 511), 0);
    EXPECT_EQ(read_code(m, 0xB2, 512), 0x1103);
    EXPECT_EQ(read_code(m, 0xA4, 0), 0x1101);  // bank 4: not on this model
    const std::pair<std::uint8_t, std::uint16_t> absent[] = {
        {0xB3, 0},      {0x33, 0},      {0x09, 0}, {0x09, 0x8000}, {0x89, 0},      {0x89, 0x8000},
        {0x49, 0},      {0x06, 0},      {0x46, 0}, {0xDC, 0x0100}, {0xBC, 0x0200}, {0x07, 0x0000},
        {0x07, 0x1000}, {0x07, 0x2001}, {0x0A, 0}, {0x98, 0},      {0x80, 0},      {0x9C, 0x0003},
    };
    for (const auto& [code, word] : absent)
        EXPECT_EQ(read_code(m, code, word), 0x1101) << std::hex << unsigned{code} << " " << word;
}

TEST(Profiles, CsCjProfilesHaveEveryArea) {
    for (const char* name : {"cj2h", "cs1h", "cj1m", "cp1h"}) {
        HeapMemory m(get(name));
        SCOPED_TRACE(name);
        EXPECT_EQ(read_code(m, 0xB3, 959), 0);
        EXPECT_EQ(read_code(m, 0x89, 4095), 0);
        EXPECT_EQ(read_code(m, 0x89, 0x8FFF), 0);
        EXPECT_EQ(read_code(m, 0x06, 31), 0);
        EXPECT_EQ(read_code(m, 0xDC, 0x010F), 0);
        EXPECT_EQ(read_code(m, 0x07, 0x100F), 0);
        EXPECT_EQ(read_code(m, 0xB0, 6143), 0);
        EXPECT_EQ(read_code(m, 0x82, 32767), 0);
    }
}

TEST(Profiles, ZeroTimersOrCountersAlone) {
    Profile p = cj2h();
    p.timers = 0;
    HeapMemory m(p);
    EXPECT_EQ(read_code(m, 0x89, 0), 0x1101);
    EXPECT_EQ(read_code(m, 0x89, 0x8000), 0);
    p = cj2h();
    p.counters = 0;
    HeapMemory n(p);
    EXPECT_EQ(read_code(n, 0x89, 0), 0);
    EXPECT_EQ(read_code(n, 0x09, 0x8000), 0x1101);
}

}  // namespace
}  // namespace fins::plc::test
