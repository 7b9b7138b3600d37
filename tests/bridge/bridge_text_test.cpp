// Issue 25: a string tag over memory bytes 80-FF. fins-bridge aborted when the JSON dump of
// such a tag's text threw; now each byte is the character of the same code point (Latin-1)
// in UTF-8, so the payload is valid JSON, and written text must be Latin-1.
#include <gtest/gtest.h>

#include <array>

#include "bridge/json_payload.hpp"
#include "bridge/poll/tag_decode.hpp"
#include "bridge_rig.hpp"

namespace fins::bridge::test {
namespace {

using nlohmann::json;

TEST(BridgeText, AStringTagsOddLengthCutsTheByteNotTheUtf8) {
    Tag tag;
    tag.type = TagType::string;
    tag.length = 3;
    tag.words = 2;
    // A á | â ã: length 3 leaves ã (E3) outside the tag.
    const std::array<std::uint8_t, 4> data{0x41, 0xE1, 0xE2, 0xE3};
    TagSample s;
    decode_words(tag, data, 0, s);
    EXPECT_EQ(s.value.text, "A\xC3\xA1\xC3\xA2");
    std::string out;
    append_json(out, TagType::string, s.value);
    EXPECT_EQ(out, "\"A\xC3\xA1\xC3\xA2\"");
}

TEST(BridgeText, WrittenTextIsLatin1AndCountedInCharacters) {
    Encoded e;
    EXPECT_EQ(encode_value(TagType::string, 2, {},
                           json("\xC2\xB0"
                                "C"),
                           e),
              std::nullopt);
    EXPECT_EQ(encode_value(TagType::string, 2, {}, json("\xC2\xB0\xC2\xB0\xC2\xB0"), e),
              "string of 3 characters is longer than the tag's 2");
    EXPECT_EQ(encode_value(TagType::string, 8, {}, json("A\xE2\x82\xAC"), e),
              "string refused: character 2 is U+20AC, above U+00FF: a PLC byte holds one "
              "character U+0000-U+00FF (Latin-1)");
    // A Sparkplug string_value is not checked for UTF-8 by protobuf.
    EXPECT_EQ(encode_value(TagType::string, 8, {}, json(std::string("A\xB0")), e),
              "string refused: byte 2 (0xB0) is not UTF-8: text must be UTF-8");
}

// An id over 128 bytes is cut to 128 for the refusal; cut inside a UTF-8 character, the
// answer's dump threw (the bridge ended).
TEST(BridgeText, AWriteResponseWithACutIdIsValidJson) {
    JsonPayload f("pre", "edge");
    const std::string id = std::string(127, 'a') + "\xC3\xA9";  // 129 bytes
    auto c =
        f.parse("pre/press1/write", json{{"id", id}, {"tag", "t"}, {"value", 1}}.dump(), false);
    ASSERT_TRUE(c);
    const auto* r = std::get_if<Refusal>(&*c);
    ASSERT_TRUE(r);
    Plc plc;
    plc.name = "press1";
    std::vector<Message> out;
    EXPECT_NO_THROW(f.write_response(plc, r->response, [&](Message&& m) { out.push_back(m); }));
    ASSERT_EQ(out.size(), 1u);
    const auto j = json::parse(out[0].payload, nullptr, false);
    ASSERT_TRUE(j.is_object()) << out[0].payload;
    EXPECT_EQ(j["ok"], false);
    EXPECT_EQ(j["id"], std::string(127, 'a') + "\xEF\xBF\xBD");  // U+FFFD
}

TEST(BridgeRun, AStringTagOverBytesAbove7FPublishesLatin1Text) {
    Rig rig;
    ASSERT_TRUE(rig.ready());
    ASSERT_TRUE(
        rig.sub.wait_topic("t/press1/fast", [](const json& j) { return j.value("full", false); }));
    auto client = rig.finsd.client();
    ASSERT_TRUE(client);
    const auto before = rig.sub.count();
    // "recipe" is D210, 8 characters: A á B C ° C.
    ASSERT_TRUE(client->write_words(fins::test::addr("D210"),
                                    std::vector<std::uint16_t>{0x41E1, 0x4243, 0xB043, 0}));
    const std::string text =
        "A\xC3\xA1"
        "BC\xC2\xB0"
        "C";
    auto m = rig.sub.wait_topic(
        "t/press1/fast",
        [&](const json& j) {
            return j.is_object() && j["values"].contains("recipe") && j["values"]["recipe"] == text;
        },
        std::chrono::seconds(15), before);
    ASSERT_TRUE(m);
    // Every message since is valid JSON: the bridge did not die on the text.
    for (const auto& r : rig.sub.messages())
        EXPECT_FALSE(r.json().is_discarded()) << r.topic << ": " << r.payload;

    // Written back through MQTT: the same bytes; beyond U+00FF is refused, nothing written.
    rig.sub.publish("t/press1/write", R"({"id":"t1","tag":"recipe","value":"µ²°"})");
    auto r = response(rig.sub, "t1");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["ok"], true) << r->dump();
    EXPECT_EQ((*r)["value"], "µ²°");
    EXPECT_EQ(fins::test::words_of(*client, "D210", 4),
              (std::vector<std::uint16_t>{0xB5B2, 0xB000, 0, 0}));
    rig.sub.publish("t/press1/write", R"({"id":"t2","tag":"recipe","value":"\u0100"})");
    r = response(rig.sub, "t2");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["ok"], false) << r->dump();
    EXPECT_NE((*r)["error"].get<std::string>().find("U+0100"), std::string::npos) << r->dump();
    EXPECT_EQ(fins::test::words_of(*client, "D210", 1), std::vector<std::uint16_t>{0xB5B2});
}

}  // namespace
}  // namespace fins::bridge::test
