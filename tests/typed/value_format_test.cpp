// The value formats every front end shares (typed/value_format.hpp): text is Latin-1 in
// UTF-8 whatever the bytes (issue 25), and numbers a format cannot hold are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "typed/value_format.hpp"

namespace fins::test {
namespace {

using typed::Format;
using W = std::vector<std::uint16_t>;

W words_of(Format f, std::vector<std::string> values) {
    auto r = typed::parse_words(f, values);
    if (auto* e = std::get_if<typed::ParseError>(&r)) {
        ADD_FAILURE() << e->message;
        return {};
    }
    return std::get<W>(r);
}

std::string refusal(Format f, std::vector<std::string> values) {
    auto r = typed::parse_words(f, values);
    if (auto* e = std::get_if<typed::ParseError>(&r)) return e->message;
    ADD_FAILURE() << "accepted";
    return {};
}

// Words 41 E1 42 43 read as ascii used to throw from the JSON dump (finsd exit 3, fins
// SIGABRT): now "AáBC", valid UTF-8 in the text and the JSON.
TEST(ValueFormat, StringBytesAbove7FReadAsLatin1) {
    auto p = typed::print_words(Format::string, W{0x41E1, 0x4243});
    ASSERT_TRUE(p);
    ASSERT_EQ(p->size(), 1u);
    EXPECT_EQ((*p)[0].json, "A\xC3\xA1" "BC");
    EXPECT_EQ((*p)[0].text, "\"A\xC3\xA1" "BC\"");
    EXPECT_EQ((*p)[0].json.dump(), "\"A\xC3\xA1" "BC\"");  // does not throw
    // B0 is the degree sign, C2 B0 in UTF-8.
    EXPECT_EQ(typed::print_words(Format::string, W{0xB043}).value()[0].json, "\xC2\xB0" "C");
}

// Every pair of bytes a word can hold prints as valid JSON, and the text writes back the
// same word (00 ends the string: a word with a 00 byte reads as what comes before it).
TEST(ValueFormat, EveryWordReadsAsTextThatWritesItBack) {
    for (unsigned w = 0; w <= 0xFFFF; ++w) {
        const W words{static_cast<std::uint16_t>(w)};
        auto p = typed::print_words(Format::string, words);
        ASSERT_TRUE(p) << w;
        const std::string text = (*p)[0].json.get<std::string>();
        ASSERT_EQ(nlohmann::json::parse((*p)[0].json.dump()), (*p)[0].json) << w;
        if ((w >> 8) == 0) {
            ASSERT_EQ(text, "") << w;
            continue;
        }
        const auto back = words_of(Format::string, {text});
        ASSERT_EQ(back, ((w & 0xFF) == 0 ? W{static_cast<std::uint16_t>(w)} : words)) << w;
    }
}

// Issue 25: memory holding any of the 65,536 word values prints in every format as text and
// JSON that dumps without throwing and parses back (a read-only finsd ended on one word).
TEST(ValueFormat, EveryWordOfEveryFormatPrintsValidJson) {
    // Bits print one value a word (print_words looped for ever on them: fuzz_formats).
    const auto bits = typed::print_words(Format::bits, W{0, 1, 0x8000});
    ASSERT_TRUE(bits);
    ASSERT_EQ(bits->size(), 3u);
    EXPECT_EQ((*bits)[0].text, "0");
    EXPECT_EQ((*bits)[2].json, true);
    for (const Format f : typed::all_formats()) {
        const std::size_t n = std::max<std::size_t>(typed::words_per_value(f), 1);
        for (unsigned w = 0; w <= 0xFFFF; ++w) {
            W words(n, static_cast<std::uint16_t>(w));
            auto p = typed::print_words(f, words);
            if (!p) {
                ASSERT_TRUE(f == Format::bcd || f == Format::bcd32) << w;  // not BCD: refused
                continue;
            }
            for (const auto& v : *p) {
                std::string dumped;
                ASSERT_NO_THROW(dumped = v.json.dump()) << typed::format_name(f) << " " << w;
                ASSERT_FALSE(nlohmann::json::parse(dumped, nullptr, false).is_discarded()) << w;
                ASSERT_FALSE(nlohmann::json::parse(nlohmann::json(v.text).dump(), nullptr, false)
                                 .is_discarded())
                    << w;
            }
        }
    }
}

TEST(ValueFormat, TextBeyondLatin1OrNotUtf8IsRefusedWithTheReason) {
    EXPECT_EQ(words_of(Format::string, {"\xC2\xB0" "C"}), W{0xB043});
    EXPECT_EQ(refusal(Format::string, {"A\xC4\x80"}),
              "cannot write that text as a string: character 2 is U+0100, above U+00FF: a PLC "
              "byte holds one character U+0000-U+00FF (Latin-1)");
    EXPECT_NE(refusal(Format::string, {"\xE2\x82\xAC"}).find("U+20AC"), std::string::npos);
    EXPECT_EQ(refusal(Format::string, {"A\xB0"}),
              "cannot write that text as a string: byte 2 (0xB0) is not UTF-8: text must be "
              "UTF-8");
    // The sentence never quotes the bad bytes: it is valid UTF-8 for a JSON error.
    EXPECT_NO_THROW(nlohmann::json(refusal(Format::string, {"\xFF\xFE"})).dump());
}

// A float the format cannot hold was stored as infinity; "--5" read as 5.
TEST(ValueFormat, NumbersTheFormatCannotHoldAreRefused) {
    EXPECT_EQ(refusal(Format::float32, {"3.5e38"}),
              "'3.5e38' is out of range for float (at most 3.40282e+38 either side of 0)");
    EXPECT_NE(refusal(Format::float32, {"-3.5e38"}).find("out of range"), std::string::npos);
    EXPECT_EQ(refusal(Format::float32, {"1e-50"}),
              "'1e-50' is too small for float (it would be 0)");
    EXPECT_EQ(refusal(Format::float64, {"1e309"}), "'1e309' is out of range for double");
    EXPECT_EQ(refusal(Format::float64, {"-1e309"}), "'-1e309' is out of range for double");
    EXPECT_EQ(words_of(Format::float32, {"3.4e38"}).at(1), 0x7F7F);
    EXPECT_EQ(words_of(Format::float32, {"0"}), (W{0, 0}));
    EXPECT_EQ(words_of(Format::float32, {"-0"}), (W{0, 0x8000}));
    // Infinity and NaN typed out are what the reads print: they write as themselves.
    EXPECT_EQ(words_of(Format::float32, {"inf"}), (W{0x0000, 0x7F80}));
    EXPECT_EQ(words_of(Format::float64, {"-inf"}), (W{0, 0, 0, 0xFFF0}));
    for (const Format f : {Format::int16, Format::uint16, Format::int32, Format::uint32,
                           Format::hex, Format::bcd, Format::bcd32, Format::float32,
                           Format::float64})
        for (const char* bad : {"--5", "+-5", "-+5", "++5", "0x-5", "-0x-5", "- 5", "+", "-"})
            EXPECT_NE(refusal(f, {bad}).find(bad), std::string::npos)
                << bad << " as " << typed::format_name(f);
    EXPECT_EQ(refusal(Format::int16, {"--5"}), "'--5' is not a valid int16 value");
    EXPECT_EQ(refusal(Format::float32, {"--5"}), "'--5' is not a valid float value");
    EXPECT_EQ(words_of(Format::int16, {"-5"}), W{0xFFFB});
    EXPECT_EQ(words_of(Format::int16, {"+5"}), W{5});
    EXPECT_EQ(words_of(Format::int16, {"-0x8000"}), W{0x8000});
}

TEST(ValueFormat, JsonNumbersTheFormatCannotHoldAreRefused) {
    std::array<std::uint16_t, 4> w{};
    EXPECT_EQ(typed::json_to_words(Format::float32, nlohmann::json(3.5e38), w),
              "3.5e+38 is out of range for float");
    EXPECT_EQ(typed::json_to_words(Format::float32, nlohmann::json(1e-50), w),
              "1e-50 is too small for float (it would be 0)");
    // JSON text cannot hold infinity (nlohmann refuses "1e309"), but a Sparkplug double
    // metric can.
    const nlohmann::json huge = std::numeric_limits<double>::infinity();
    EXPECT_EQ(typed::json_to_words(Format::float64, huge, w),
              "the number is out of range for double");
    EXPECT_EQ(typed::json_to_words(Format::float32, huge, w),
              "the number is out of range for float");
    EXPECT_EQ(typed::json_to_words(Format::float32, nlohmann::json(3.4e38), w), std::nullopt);
    EXPECT_EQ(w[1], 0x7F7F);
}

}  // namespace
}  // namespace fins::test
