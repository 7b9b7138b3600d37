// The bridge's tag types are src/typed's value formats (one table for the CLI, the web
// API and the bridge): names, sizes, JSON in and out.
#include "bridge/tag_type.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace fins::bridge {
namespace {

using nlohmann::json;

TEST(BridgeTagType, NamesAndSizesAreTheCliFormats) {
    for (std::string_view name :
         {"int16", "uint16", "int32", "uint32", "float", "double", "bcd", "bcd32", "string"}) {
        const auto t = parse_tag_type(name);
        ASSERT_TRUE(t) << name;
        EXPECT_EQ(*t, typed::parse_format(name)) << name;
        EXPECT_EQ(tag_type_name(*t), name);
        if (*t != TagType::string) {
            EXPECT_EQ(tag_words(*t, 0), typed::words_per_value(*t)) << name;
        }
    }
    EXPECT_EQ(parse_tag_type("bool"), TagType::bits);
    EXPECT_EQ(tag_type_name(TagType::bits), "bool");
    EXPECT_EQ(tag_words(TagType::bits, 0), 1u);
    EXPECT_EQ(tag_words(TagType::string, 5), 3u);
    EXPECT_FALSE(parse_tag_type("hex"));  // a way of printing, not a tag type
    EXPECT_FALSE(parse_tag_type("int8"));
}

TEST(BridgeTagType, JsonRoundTripsThroughTheSharedConversions) {
    const auto round_trip = [](TagType t, const json& in) {
        Encoded e;
        EXPECT_FALSE(encode_value(t, 8, {}, in, e)) << in;
        TagValue v;
        v.words = e.words;
        return to_json(t, v);
    };
    EXPECT_EQ(round_trip(TagType::int16, -2), -2);
    EXPECT_EQ(round_trip(TagType::uint32, 4000000000u), 4000000000u);
    EXPECT_EQ(round_trip(TagType::float32, 1.5), 1.5);
    EXPECT_EQ(round_trip(TagType::float64, -0.25), -0.25);
    EXPECT_EQ(round_trip(TagType::bcd, 1234), 1234);
    EXPECT_EQ(round_trip(TagType::bcd32, 12345678), 12345678);
    EXPECT_EQ(round_trip(TagType::bits, true), true);
    // The CLI's words for the same value are the bridge's.
    auto cli = typed::parse_words(TagType::bcd32, {"12345678"});
    ASSERT_TRUE(std::holds_alternative<std::vector<std::uint16_t>>(cli));
    Encoded e;
    ASSERT_FALSE(encode_value(TagType::bcd32, 0, {}, json(12345678), e));
    EXPECT_EQ(std::get<std::vector<std::uint16_t>>(cli),
              (std::vector<std::uint16_t>{e.words[0], e.words[1]}));
}

TEST(BridgeTagType, RefusesWhatDoesNotFitTheTypeOrTheTag) {
    Encoded e;
    EXPECT_EQ(encode_value(TagType::int16, 0, {}, json(40000), e),
              "40000 is out of range for int16 (-32768 to 32767)");
    EXPECT_EQ(encode_value(TagType::int16, 0, {}, json(1.5), e), "int16 needs an integer, not 1.5");
    EXPECT_EQ(encode_value(TagType::float32, 0, {}, json("hot"), e), "float needs a JSON number");
    EXPECT_EQ(encode_value(TagType::bcd, 0, {}, json(10000), e),
              "10000 is out of range for bcd (0 to 9999)");
    EXPECT_EQ(encode_value(TagType::bits, 0, {}, json(2), e), "bool needs true, false, 0 or 1");
    EXPECT_EQ(encode_value(TagType::float32, 0, {std::nullopt, 100.0}, json(101), e),
              "101 is above the tag's maximum 100");
    EXPECT_EQ(encode_value(TagType::string, 3, {}, json("abcd"), e),
              "string of 4 characters is longer than the tag's 3");
    // A word pattern that is not BCD, or a float that is NaN, is null, never a number.
    TagValue v;
    v.words = {0x00AB, 0, 0, 0};
    EXPECT_EQ(to_json(TagType::bcd, v), nullptr);
    v.words = {0x0000, 0x7FC0, 0, 0};  // NaN, low word first
    EXPECT_EQ(to_json(TagType::float32, v), nullptr);
}

}  // namespace
}  // namespace fins::bridge
