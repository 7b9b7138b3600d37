// The planner: tags in, frames out (plan.hpp).
#include "bridge/poll/plan.hpp"

#include <gtest/gtest.h>

#include "bridge/bridge_test_support.hpp"

namespace fins::bridge {
namespace {

using test::one_group;
using test::parse_ok;

Plan plan_of(const std::string& tags, const std::string& extra = "") {
    auto c = parse_ok(one_group(tags, extra));
    if (c.plcs.empty()) return {};
    const auto& g = c.plcs[0].groups[0];
    return plan_group(g.tags, g.gap_words);
}

std::string tag(const std::string& name, const std::string& address, const std::string& type) {
    return "{name=\"" + name + "\",address=\"" + address + "\",type=\"" + type + "\"},";
}

TEST(Plan, ContiguousTagsOfOneAreaAreOneRead) {
    auto p =
        plan_of(tag("a", "D100", "int16") + tag("b", "D101", "int32") + tag("c", "D103", "float"));
    ASSERT_EQ(p.frames.size(), 1u);
    EXPECT_EQ(p.frames[0].kind, PlannedFrame::Kind::read);
    EXPECT_EQ(p.frames[0].start, (MemoryAddress{0x82, 100, 0}));
    EXPECT_EQ(p.frames[0].count, 5);
    EXPECT_EQ(p.slots[1].offset, 1);
    EXPECT_EQ(p.slots[2].offset, 3);
}

TEST(Plan, GapLimitSplitsRuns) {
    const auto tags = tag("a", "D100", "int16") + tag("b", "D101", "int16") +
                      tag("c", "D120", "int16") + tag("d", "D121", "int16");
    auto near = plan_of(tags, "gap_words = 20\n");
    ASSERT_EQ(near.frames.size(), 1u);
    EXPECT_EQ(near.frames[0].count, 22);
    auto apart = plan_of(tags, "gap_words = 10\n");
    ASSERT_EQ(apart.frames.size(), 2u);
    EXPECT_EQ(apart.frames[0].count, 2);
    EXPECT_EQ(apart.frames[1].start.word, 120);
}

TEST(Plan, AreasAreNeverMerged) {
    auto p = plan_of(tag("a", "D100", "int16") + tag("b", "D101", "int16") +
                     tag("c", "W100", "int16") + tag("d", "W101", "int16"));
    ASSERT_EQ(p.frames.size(), 2u);
    EXPECT_EQ(p.frames[0].start.area_code, 0x82);  // DM word
    EXPECT_EQ(p.frames[1].start.area_code, 0xB1);  // WR word
}

TEST(Plan, AReadNeverExceeds999Words) {
    // 0..998 and 999..: two frames although the gap is 0.
    auto p = plan_of(tag("a", "D0", "int16") + tag("b", "D998", "int16") +
                         tag("c", "D999", "int16") + tag("d", "D1000", "int16"),
                     "gap_words = 999\n");
    ASSERT_EQ(p.frames.size(), 2u);
    EXPECT_EQ(p.frames[0].count, 999);
    EXPECT_EQ(p.frames[1].start.word, 999);
}

TEST(Plan, ScatteredPointsShareOneMultipleRead) {
    auto p = plan_of(tag("a", "D100", "int16") + tag("b", "D5000", "int32") +
                     tag("run", "CIO0.03", "bool") + tag("done", "T5", "bool"));
    ASSERT_EQ(p.frames.size(), 1u);
    const auto& f = p.frames[0];
    EXPECT_EQ(f.kind, PlannedFrame::Kind::multiple_read);
    ASSERT_EQ(f.items.size(), 5u);  // a, b (2 words), CIO0 word, T5 flag
    EXPECT_EQ(f.items[0], (MemoryAddress{0x82, 100, 0}));
    EXPECT_EQ(f.items[1], (MemoryAddress{0x82, 5000, 0}));
    EXPECT_EQ(f.items[2], (MemoryAddress{0x82, 5001, 0}));
    EXPECT_EQ(f.items[3], (MemoryAddress{0xB0, 0, 0}));  // the word holding the bit
    EXPECT_EQ(f.items[4], (MemoryAddress{0x09, 5, 0}));  // completion flag
    EXPECT_EQ(p.slots[3].offset, 4);
}

TEST(Plan, MultipleReadHolds167Elements) {
    std::string tags;
    for (int i = 0; i < 200; ++i)
        tags += tag("t" + std::to_string(i), "D" + std::to_string(i * 100), "int16");
    auto p = plan_of(tags);
    ASSERT_EQ(p.frames.size(), 2u);
    EXPECT_EQ(p.frames[0].items.size(), 167u);
    EXPECT_EQ(p.frames[1].items.size(), 33u);
    for (std::size_t i = 0; i < 200; ++i)
        EXPECT_EQ(p.slots[i].frame, i < 167 ? 0 : 1);
}

TEST(Plan, ALoneWordTagIsAPlainRead) {
    auto p = plan_of(tag("a", "D100", "int16"));
    ASSERT_EQ(p.frames.size(), 1u);
    EXPECT_EQ(p.frames[0].kind, PlannedFrame::Kind::read);
    EXPECT_EQ(p.frames[0].count, 1);
}

TEST(Plan, BitsOfOneWordShareTheRead) {
    auto p = plan_of(tag("a", "CIO10.00", "bool") + tag("b", "CIO10.15", "bool") +
                     tag("c", "CIO11.01", "bool"));
    ASSERT_EQ(p.frames.size(), 1u);
    EXPECT_EQ(p.frames[0].kind, PlannedFrame::Kind::read);
    EXPECT_EQ(p.frames[0].start, (MemoryAddress{0xB0, 10, 0}));
    EXPECT_EQ(p.frames[0].count, 2);
    EXPECT_EQ(p.slots[2].offset, 1);
}

TEST(Plan, TheBitsOfOneWordShareTheScatteredPointsFrame) {
    // fins_bridge_load's group: 10 bits of CIO0 and two scattered words were three frames
    // (01 01 x 1 word, 01 04); the word of bits is one more 01 04 element.
    auto p = plan_of(tag("r0", "CIO0.00", "bool") + tag("r1", "CIO0.01", "bool") +
                     tag("r9", "CIO0.09", "bool") + tag("x", "D1000", "int16") +
                     tag("y", "D1100", "int16"));
    ASSERT_EQ(p.frames.size(), 1u);
    ASSERT_EQ(p.frames[0].kind, PlannedFrame::Kind::multiple_read);
    ASSERT_EQ(p.frames[0].items.size(), 3u);
    EXPECT_EQ(p.frames[0].items[0], (MemoryAddress{0xB0, 0, 0}));  // CIO word
    // Every bit points at the one element of its word.
    EXPECT_EQ(p.slots[0].offset, 0);
    EXPECT_EQ(p.slots[1].offset, 0);
    EXPECT_EQ(p.slots[2].offset, 0);
    EXPECT_EQ(p.slots[3].offset, 1);
    EXPECT_EQ(p.slots[4].offset, 2);
    // The word of bits alone is still a plain read.
    auto alone = plan_of(tag("r0", "CIO0.00", "bool") + tag("r1", "CIO0.01", "bool"));
    ASSERT_EQ(alone.frames.size(), 1u);
    EXPECT_EQ(alone.frames[0].kind, PlannedFrame::Kind::read);
    EXPECT_EQ(alone.frames[0].count, 1);
    EXPECT_EQ(alone.slots[1].offset, 0);
}

TEST(Plan, DescribeNamesEveryFrameAndTag) {
    const auto tags = tag("a", "D100", "int16") + tag("b", "D101", "int16") +
                      tag("c", "D9000", "int16") + tag("d", "T5", "bool");
    auto c = parse_ok(one_group(tags));
    const auto& g = c.plcs[0].groups[0];
    EXPECT_EQ(describe_plan(plan_group(g.tags, g.gap_words), g.tags),
              "01 01 D100 x 2 words (82 0064): a=D100 b=D101\n"
              "01 04 2 elements: c=D9000 d=T5\n");
}

}  // namespace
}  // namespace fins::bridge
