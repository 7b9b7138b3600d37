// Where a scenario's errors point (issue 26 point 7): positions inside multi-line strings
// and after escape sequences, counted in characters (not bytes); a non-ASCII character
// named as one; an address past its area's end named with the area's range.
#include <gtest/gtest.h>

#include <string>

#include "plc/plc.hpp"
#include "scenario/scenario.hpp"
#include "scenario_support.hpp"

namespace fins::scenario {
namespace {

using test::tag;

// The compile error of a link `D1 = expr`, the expression written in the file as `raw`
// with its opening quote at line 3, column 8 (`expr = ...`).
CompileError link_error(std::string text, std::string raw) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef link = tag("D1", SignalKind::link);
    link.input.text = std::move(text);
    link.input.raw = std::move(raw);
    link.input.pos = {3, 8, 0};
    def.tags.push_back(link);
    auto s = Scenario::compile(std::move(def), plc);
    EXPECT_FALSE(s.has_value());
    return s ? CompileError{} : s.error();
}

TEST(ScenarioPositions, InsideAMultiLineString) {
    // expr = """
    // 2 * D100 +
    //   Q5"""
    const auto e = link_error("2 * D100 +\n  Q5", "\"\"\"\n2 * D100 +\n  Q5\"\"\"");
    EXPECT_EQ(e.message, "'Q5' is neither an address nor a name");
    EXPECT_EQ(e.pos.line, 5u);
    EXPECT_EQ(e.pos.column, 3u);
}

TEST(ScenarioPositions, InsideAMultiLineLiteralStringWithoutAFirstLineBreak) {
    const auto e = link_error("1 +\n (2 *", "'''1 +\n (2 *'''");
    EXPECT_EQ(e.message, "expression ends where a value is expected");
    EXPECT_EQ(e.pos.line, 4u);
    EXPECT_EQ(e.pos.column, 6u);  // the closing '''
}

TEST(ScenarioPositions, AfterEscapeSequences) {
    // expr = "1 +\t\tQ5": each \t is two characters of the file, one of the value.
    const auto e = link_error("1 +\t\tQ5", "\"1 +\\t\\tQ5\"");
    EXPECT_EQ(e.message, "'Q5' is neither an address nor a name");
    EXPECT_EQ(e.pos.line, 3u);
    EXPECT_EQ(e.pos.column, 16u);
    // \u00E9 is six characters of the file; a \n escape starts a line of the value but
    // not of the file.
    const auto u = link_error("\xC3\xA9 + 1", "\"\\u00E9 + 1\"");
    EXPECT_EQ(u.message, "unexpected character '\xC3\xA9'");
    EXPECT_EQ(u.pos.column, 9u);
    const auto n = link_error("1 +\n Q5", "\"1 +\\n Q5\"");
    EXPECT_EQ(n.message, "'Q5' is neither an address nor a name");
    EXPECT_EQ(n.pos.line, 3u);
    EXPECT_EQ(n.pos.column, 15u);
}

TEST(ScenarioPositions, ALineEndingBackslashGivesNothing) {
    // expr = """1 + <backslash, line break>
    //           Q5"""
    const auto e = link_error("1 + Q5", "\"\"\"1 + \\\n          Q5\"\"\"");
    EXPECT_EQ(e.pos.line, 4u);
    EXPECT_EQ(e.pos.column, 11u);
}

TEST(ScenarioPositions, ANonAsciiCharacterIsNamedAndCountedAsOneColumn) {
    // expr = "é + 1" / "D1 + Dé" / "1 + D1é": the column of the character, in characters.
    auto e = link_error("\xC3\xA9\xC3\xA9 + 1", "\"\xC3\xA9\xC3\xA9 + 1\"");
    EXPECT_EQ(e.message, "unexpected character '\xC3\xA9'");
    EXPECT_EQ(e.pos.column, 9u);
    e = link_error("\xC3\xA9 + D2 $", "\"\xC3\xA9 + D2 $\"");  // the first error only
    EXPECT_EQ(e.pos.column, 9u);
    e = link_error("2 * D2\xC3\xA9", "\"2 * D2\xC3\xA9\"");
    EXPECT_EQ(e.message, "unexpected character '\xC3\xA9'");
    EXPECT_EQ(e.pos.column, 15u);
    e = link_error("\xC3\xA9\xC3\xA9 + $", "\"\xC3\xA9\xC3\xA9 + $\"");
    EXPECT_EQ(e.message, "unexpected character '\xC3\xA9'");
    // Without the file's text (an API user): counted from the quote, still in characters.
    e = link_error("1 + 2 \xE2\x82\xAC", "");
    EXPECT_EQ(e.message, "unexpected character '\xE2\x82\xAC'");
    EXPECT_EQ(e.pos.column, 15u);
}

TEST(ScenarioPositions, AnAddressPastItsAreaNamesTheRange) {
    auto e = link_error("D40000 + 1", "\"D40000 + 1\"");
    EXPECT_EQ(e.message, "D40000 is out of range: D0-D32767");
    EXPECT_EQ(e.pos.column, 9u);
    e = link_error("W600", "\"W600\"");
    EXPECT_EQ(e.message, "W600 is out of range: W0-W511");
    e = link_error("E2_40000", "\"E2_40000\"");
    EXPECT_EQ(e.message, "E2_40000 is out of range: E2_0-E2_32767");
    e = link_error("W0.16", "\"W0.16\"");
    EXPECT_EQ(e.message, "W0.16 is out of range: bits 00-15");
    // A tag's own address, too.
    plc::Plc plc;
    ScenarioDef def;
    def.tags.push_back(tag("D40000", SignalKind::constant));
    auto s = Scenario::compile(std::move(def), plc);
    ASSERT_FALSE(s.has_value());
    EXPECT_EQ(s.error().message, "D40000 is out of range: D0-D32767");
}

}  // namespace
}  // namespace fins::scenario
