// The command list of W342 5-1-1 and the execution conditions of 5-1-2.
#include <set>

#include <gtest/gtest.h>

#include "fins/command_table.hpp"

namespace fins {
namespace {

const CommandInfo& get(std::uint8_t main, std::uint8_t sub) {
    const auto* c = find_command({main, sub});
    EXPECT_NE(c, nullptr) << std::hex << int(main) << " " << int(sub);
    static const CommandInfo none{};
    return c ? *c : none;
}

// W342 5-1-1 plus 02 40, the Loop Control Board's ITEM read (seed 001, "seed 001").
TEST(CommandTable, EveryCommandOf511AndTheLoopControlItemRead) {
    const std::set<std::uint16_t> expected{
        0x0101, 0x0102, 0x0103, 0x0104, 0x0105, 0x0201, 0x0202, 0x0203, 0x0240, 0x0306,
        0x0307, 0x0308, 0x0401, 0x0402, 0x0501, 0x0502, 0x0601, 0x0620, 0x0701, 0x0702,
        0x0920, 0x0C01, 0x0C02, 0x0C03, 0x2101, 0x2102, 0x2103, 0x2140, 0x2141, 0x2201,
        0x2202, 0x2203, 0x2204, 0x2205, 0x2207, 0x2208, 0x220A, 0x220B, 0x220C, 0x2215,
        0x2220, 0x2301, 0x2302, 0x2803, 0x2804, 0x2805};
    std::set<std::uint16_t> seen;
    std::set<std::string_view> sections;
    std::uint16_t previous = 0;
    for (const auto& c : command_table()) {
        SCOPED_TRACE(std::string(c.name));
        EXPECT_TRUE(seen.insert(c.code.value()).second);
        EXPECT_GT(c.code.value(), previous);
        previous = c.code.value();
        EXPECT_FALSE(c.name.empty());
        EXPECT_TRUE(c.section.substr(0, 4) == "5-3-" || c.section == "seed 001");
        EXPECT_TRUE(sections.insert(c.section).second);
        EXPECT_EQ(find_command(c.code), &c);
    }
    EXPECT_EQ(seen, expected);
    EXPECT_EQ(find_command({0x01, 0x06}), nullptr);
    EXPECT_EQ(find_command({0xFF, 0xFF}), nullptr);
    EXPECT_EQ(find_command({0x00, 0x00}), nullptr);
    EXPECT_EQ(get(0x01, 0x01).name, "MEMORY AREA READ");
    EXPECT_EQ(get(0x28, 0x05).section, "5-3-48");
    EXPECT_EQ(get(0x09, 0x20).section, "5-3-21");
}

// The write-protected-from-network column (5-1-2 note 5 / 5-1-1 note 1). 09 20 is
// accepted: its reads are allowed (5-3-21, 5-3-23), its handler refuses MESSAGE CLEAR.
TEST(CommandTable, NetworkWriteProtection) {
    const std::set<std::uint16_t> refused{0x0102, 0x0103, 0x0105, 0x0202, 0x0203, 0x0307, 0x0308,
                                          0x0401, 0x0402, 0x0702, 0x0C01, 0x2101, 0x2103, 0x2141,
                                          0x2203, 0x2204, 0x2205, 0x2207, 0x2208, 0x220A, 0x220B,
                                          0x220C, 0x2215, 0x2220, 0x2301, 0x2302};
    for (const auto& c : command_table())
        EXPECT_EQ(c.conditions.network_write_protected, refused.count(c.code.value()) == 0)
            << c.name;
}

// 0C 01 is the one "Disabled" row the table leaves to its handler: its 3001 answer must
// carry the holder's address (5-3-24), which the generic check cannot write. 21 03 is
// refused although 5-1-2 says OK: 5-3-29 and the 0C 01 / 0C 02 pages say No.
TEST(CommandTable, AccessRightHeldElsewhere) {
    const std::set<std::uint16_t> refused{0x0202, 0x0203, 0x0307, 0x0308, 0x0401, 0x0402, 0x0702,
                                          0x2101, 0x2103, 0x2141, 0x2203, 0x2204, 0x2205, 0x2207,
                                          0x2208, 0x220A, 0x220B, 0x220C, 0x2215, 0x2220};
    for (const auto& c : command_table())
        EXPECT_EQ(c.conditions.access_right_elsewhere, refused.count(c.code.value()) == 0)
            << c.name;
}

TEST(CommandTable, ModesAndProtection) {
    for (const auto& c : command_table()) {
        const auto v = c.code.value();
        const bool program_only = v == 0x0307 || v == 0x0308 || v == 0x2220;
        const bool not_in_run = program_only || v == 0x2301 || v == 0x2302;
        EXPECT_EQ(c.conditions.run, !not_in_run) << c.name;
        EXPECT_EQ(c.conditions.monitor, !program_only) << c.name;
        EXPECT_EQ(c.conditions.program, v != 0x0620) << c.name;
        EXPECT_EQ(c.conditions.um_read_protected, v != 0x0306) << c.name;
        // 22 0C: "No (note 1)" -- program-to-file still runs, so the row accepts it and
        // the handler refuses file-to-program (tests/server/handlers/file_transfer_test.cpp).
        const bool dip = v == 0x0202 || v == 0x0203 || v == 0x0307 || v == 0x0308;
        EXPECT_EQ(c.conditions.dip_write_protected, !dip) << c.name;
    }
}

// Choices pinned where 5-1-2 is blank or qualified (see command_table.cpp).
TEST(CommandTable, ManualGapsPinned) {
    // 07 02: blank network column -> Disabled (5-3-20, W596 2-6).
    EXPECT_FALSE(get(0x07, 0x02).conditions.network_write_protected);
    // 09 20: "Disabled (MESSAGE CLEAR only)" -> accepted here; the handler refuses CLEAR,
    // under network write protection too (the reads are OK there: 5-3-21, 5-3-23).
    EXPECT_TRUE(get(0x09, 0x20).conditions.access_right_elsewhere);
    EXPECT_TRUE(get(0x09, 0x20).conditions.network_write_protected);
    // 21 03: 5-1-2 says OK for the access right, 5-3-29 and the 0C 01 / 0C 02 pages say
    // No; the pages decide.
    EXPECT_FALSE(get(0x21, 0x03).conditions.access_right_elsewhere);
    // 22 0B / 22 0C: "OK (note)" in RUN/MONITOR counts as accepted.
    EXPECT_TRUE(get(0x22, 0x0B).conditions.run);
    EXPECT_TRUE(get(0x22, 0x0C).conditions.monitor);
}

}  // namespace
}  // namespace fins
