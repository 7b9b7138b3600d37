// The JSON payload format and the write-value checks (pure: no broker, no PLC).
#include "bridge/json_payload.hpp"

#include <gtest/gtest.h>

#include "bridge_test_support.hpp"

namespace fins::bridge {
namespace {

TEST(JsonPayload, ParsesAWriteCommand) {
    JsonPayload f("pre", "edge");
    auto c = f.parse("pre/press1/write", R"({"id":"a","tag":"temp","value":1.5,"ts":5})", false);
    ASSERT_TRUE(c);
    const auto* w = std::get_if<WriteCommand>(&*c);
    ASSERT_TRUE(w);
    EXPECT_EQ(w->plc, "press1");
    EXPECT_EQ(w->id, "\"a\"");  // the id's JSON text
    EXPECT_EQ(w->tag, "temp");
    EXPECT_EQ(w->value, 1.5);
    EXPECT_EQ(w->ts_ms, 5);
    EXPECT_FALSE(f.parse("other/press1/write", "{}", false));
    EXPECT_FALSE(f.parse("pre/press1/write/response", "{}", false));
}

TEST(JsonPayload, IdsKeepTheirJsonType) {
    JsonPayload f("pre", "edge");
    auto number = f.parse("pre/p/write", R"({"id":5,"tag":"t","value":1})", false);
    auto text = f.parse("pre/p/write", R"({"id":"5","tag":"t","value":1})", false);
    ASSERT_TRUE(number && text);
    const auto* n = std::get_if<WriteCommand>(&*number);
    const auto* t = std::get_if<WriteCommand>(&*text);
    ASSERT_TRUE(n && t);
    EXPECT_NE(n->id, t->id);  // two ids, two memory keys
    // Echoed with the type they came with.
    Plc plc;
    plc.name = "p";
    std::vector<Message> out;
    const Sink sink = [&](Message&& m) { out.push_back(std::move(m)); };
    f.write_response(plc, {n->id, true, 0, nlohmann::json(1), ""}, sink);
    f.write_response(plc, {t->id, true, 0, nlohmann::json(1), ""}, sink);
    f.write_response(plc, {"", false, std::nullopt, std::nullopt, "the command has no id"}, sink);
    ASSERT_EQ(out.size(), 3u);
    EXPECT_EQ(out[0].topic, "pre/p/write/response");
    EXPECT_EQ(nlohmann::json::parse(out[0].payload)["id"], nlohmann::json(5));
    EXPECT_EQ(nlohmann::json::parse(out[1].payload)["id"], nlohmann::json("5"));
    EXPECT_EQ(nlohmann::json::parse(out[2].payload)["id"], nlohmann::json(""));
}

TEST(JsonPayload, AWriteToAnEmptyPlcNameIsParsedToBeRefused) {
    JsonPayload f("pre", "edge");
    auto c = f.parse("pre//write", R"({"id":"a","tag":"t","value":1})", false);
    ASSERT_TRUE(c);
    const auto* w = std::get_if<WriteCommand>(&*c);
    ASSERT_TRUE(w);
    EXPECT_EQ(w->plc, "");
}

TEST(JsonPayload, RefusesBadCommands) {
    JsonPayload f("pre", "edge");
    const auto refusal = [&](const std::string& text, bool retained = false) {
        auto c = f.parse("pre/p/write", text, retained);
        const auto* r = c ? std::get_if<Refusal>(&*c) : nullptr;
        EXPECT_TRUE(r) << text;
        if (r) {
            EXPECT_EQ(r->plc, "p") << text;
        }
        return r ? r->response.error : std::string();
    };
    EXPECT_EQ(refusal("nope"), "the command is not a JSON object");
    EXPECT_EQ(refusal("[1]"), "the command is not a JSON object");
    EXPECT_EQ(refusal(R"({"tag":"t","value":1})"), "the command has no id");
    EXPECT_EQ(refusal(R"({"id":true,"tag":"t","value":1})"), "id must be a string or an integer");
    EXPECT_NE(refusal(R"({"id":"a","tag":"t","value":1})", true).find("retained"),
              std::string::npos);
    EXPECT_EQ(refusal(R"({"id":"a","tag":"t","value":1,"x":2})"), "unknown key 'x'");
    EXPECT_EQ(refusal(R"({"id":"a","value":1})"), "tag must be a string");
    EXPECT_EQ(refusal(R"({"id":"a","tag":"t"})"), "the command has no value");
    EXPECT_EQ(refusal(R"({"id":"a","tag":"t","value":1,"ts":"now"})"),
              "ts must be an integer (ms since the epoch)");
}

TEST(JsonPayload, ValuesCarryErrorsNeverStaleValues) {
    auto c = test::parse_ok(test::one_group(
        R"({name="a",address="D0",type="int16"},{name="b",address="D1",type="float"},)"
        R"({name="c",address="D3.0",type="bool"})"));
    ASSERT_EQ(c.plcs.size(), 1u);
    const auto& plc = c.plcs[0];
    std::vector<TagSample> s(3);
    s[0].value.words[0] = 0xFFFF;  // -1
    s[0].changed = true;
    s[1].error = make_error_code(EndCode::address_range_error);
    s[1].changed = true;
    JsonPayload f("pre", "edge");
    std::vector<Message> out;
    const Sink sink = [&](Message&& m) { out.push_back(std::move(m)); };
    f.values({&plc, &plc.groups[0], s, 1234, false}, sink);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].topic, "pre/p/g");
    EXPECT_EQ(
        out[0].payload,
        R"({"ts":1234,"values":{"a":-1,"b":{"end_code":"1103","error":"1103 address range error: )" +
            std::string(find_end_code(0x1103)->message) + R"("}}})");
    // Nothing changed: no message; a full snapshot carries every tag.
    for (auto& t : s)
        t.changed = false;
    f.values({&plc, &plc.groups[0], s, 1235, false}, sink);
    EXPECT_EQ(out.size(), 1u);
    f.values({&plc, &plc.groups[0], s, 1236, true}, sink);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_NE(out[1].payload.find(R"("c":false},"full":true})"), std::string::npos)
        << out[1].payload;
}

TEST(TagType, WriteValuesAreTypeAndRangeChecked) {
    Encoded e;
    EXPECT_FALSE(encode_value(TagType::int16, 0, {}, -32768, e));
    EXPECT_EQ(e.count, 1u);
    EXPECT_EQ(e.words[0], 0x8000);
    EXPECT_TRUE(encode_value(TagType::int16, 0, {}, 32768, e));
    EXPECT_TRUE(encode_value(TagType::uint32, 0, {}, -1, e));
    EXPECT_TRUE(encode_value(TagType::int32, 0, {}, 1.5, e));
    EXPECT_TRUE(encode_value(TagType::bcd, 0, {}, 10000, e));
    EXPECT_FALSE(encode_value(TagType::bcd, 0, {}, 1234, e));
    EXPECT_EQ(e.words[0], 0x1234);
    EXPECT_TRUE(encode_value(TagType::float32, 0, {}, "1", e));
    EXPECT_TRUE(encode_value(TagType::float32, 0, {}, 1e39, e));
    EXPECT_TRUE(encode_value(TagType::float32, 0, {0.0, 10.0}, 11, e));
    EXPECT_TRUE(encode_value(TagType::float32, 0, {0.0, 10.0}, -0.5, e));
    EXPECT_FALSE(encode_value(TagType::float32, 0, {0.0, 10.0}, 10, e));
    EXPECT_FALSE(encode_value(TagType::bits, 0, {}, true, e));
    EXPECT_TRUE(e.bit);
    EXPECT_TRUE(encode_value(TagType::bits, 0, {}, 2, e));
    EXPECT_TRUE(encode_value(TagType::string, 4, {}, "abcde", e));
    EXPECT_TRUE(encode_value(TagType::string, 4, {}, 12, e));
    EXPECT_FALSE(encode_value(TagType::string, 4, {}, "abcd", e));
}

}  // namespace
}  // namespace fins::bridge
