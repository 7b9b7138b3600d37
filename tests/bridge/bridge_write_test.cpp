// fins-bridge's write path end to end (docs/bridge.md "Writes"): commands published to
// {prefix}/{plc}/write are checked, executed once, read back and answered; retained ones,
// bad ones and those for an offline PLC are refused and change nothing.
#include <gtest/gtest.h>

#include "bridge_rig.hpp"

namespace fins::bridge::test {
namespace {

using nlohmann::json;

TEST(BridgeRun, WritesAreCheckedExecutedOnceAndReadBack) {
    Rig rig;
    ASSERT_TRUE(rig.ready());
    ASSERT_TRUE(rig.sub.wait_topic("t/press1/status",
                                   [](const json& j) { return j["state"] == "online"; }));
    auto client = rig.finsd.client();
    ASSERT_TRUE(client);

    rig.sub.publish("t/press1/write", R"({"id":"w1","tag":"temp","value":21.5})");
    auto r = response(rig.sub, "w1");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["ok"], true) << r->dump();
    EXPECT_EQ((*r)["end_code"], "0000");
    EXPECT_EQ((*r)["value"], 21.5);
    EXPECT_EQ(client->read_float(fins::test::addr("D200")).value_or(0), 21.5f);

    // The same id again: answered again, not executed again.
    ASSERT_TRUE(client->write_float(fins::test::addr("D200"), 7.0f));
    const auto from = rig.sub.count();
    rig.sub.publish("t/press1/write", R"({"id":"w1","tag":"temp","value":21.5})");
    auto again = rig.sub.wait_topic(
        "t/press1/write/response", [](const json& j) { return j.value("id", "") == "w1"; },
        std::chrono::seconds(15), from);
    ASSERT_TRUE(again);
    EXPECT_EQ(again->json(), *r);
    EXPECT_EQ(responses(rig.sub, "w1"), 2u);
    EXPECT_EQ(client->read_float(fins::test::addr("D200")).value_or(0), 7.0f);

    rig.sub.publish("t/press1/write", R"({"id":"b1","tag":"run","value":true})");
    r = response(rig.sub, "b1");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["value"], true) << r->dump();
    EXPECT_EQ(
        client->read_bits(fins::test::addr("CIO0.00"), 1).value_or(std::vector<bool>{false})[0],
        true);

    rig.sub.publish("t/press1/write", R"({"id":"s1","tag":"recipe","value":"AB12"})");
    r = response(rig.sub, "s1");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["value"], "AB12") << r->dump();

    rig.sub.publish("t/press1/write", R"({"id":"u1","tag":"count","value":4000000000})");
    r = response(rig.sub, "u1");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["value"], 4000000000u) << r->dump();
}

TEST(BridgeRun, BadCommandsAreAnsweredAndChangeNothing) {
    Rig rig;
    ASSERT_TRUE(rig.ready());
    ASSERT_TRUE(rig.sub.wait_topic("t/press1/status",
                                   [](const json& j) { return j["state"] == "online"; }));
    auto client = rig.finsd.client();
    ASSERT_TRUE(client);
    ASSERT_TRUE(
        client->write_words(fins::test::addr("D100"), std::vector<std::uint16_t>{5, 0, 0, 0}));
    ASSERT_TRUE(client->write_float(fins::test::addr("D200"), 3.0f));
    const auto old_ts = std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                                           std::chrono::system_clock::now().time_since_epoch())
                                           .count() -
                                       60000);
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"x1", R"({"id":"x1","tag":"nope","value":1})"},
        {"x2", R"({"id":"x2","tag":"speed","value":1})"},                     // not writable
        {"x3", R"({"id":"x3","tag":"temp","value":"hot"})"},                  // wrong type
        {"x4", R"({"id":"x4","tag":"temp","value":1000})"},                   // above max 500
        {"x5", R"({"id":"x5","tag":"count","value":-1})"},                    // uint32 range
        {"x6", R"({"id":"x6","tag":"count","value":1.5})"},                   // not an integer
        {"x7", R"({"id":"x7","tag":"temp","value":1,"ts":)" + old_ts + "}"},  // older than the TTL
        {"x8", R"({"id":"x8","tag":"temp"})"},                                // no value
        {"x9", R"({"id":"x9","tag":"recipe","value":"much too long"})"},
        {"x10", R"({"id":"x10","tag":"temp","value":2,"extra":1})"},
    };
    for (const auto& [id, text] : bad)
        rig.sub.publish("t/press1/write", text);
    rig.sub.publish("t/press1/write", "not json at all");
    for (const auto& [id, text] : bad) {
        auto r = response(rig.sub, id);
        ASSERT_TRUE(r) << id;
        EXPECT_EQ((*r)["ok"], false) << id;
        EXPECT_TRUE((*r)["error"].is_string()) << id;
        EXPECT_TRUE((*r)["end_code"].is_null()) << id;
    }
    auto garbage = rig.sub.wait_topic("t/press1/write/response", [](const json& j) {
        return j["id"] == "" && j["error"] == "the command is not a JSON object";
    });
    EXPECT_TRUE(garbage);
    EXPECT_EQ(client->read_float(fins::test::addr("D200")).value_or(0), 3.0f);
    EXPECT_EQ(
        client->read_words(fins::test::addr("D100"), 1).value_or(std::vector<std::uint16_t>{})[0],
        5);
    EXPECT_EQ(
        client->read_words(fins::test::addr("D202"), 2).value_or(std::vector<std::uint16_t>{}),
        (std::vector<std::uint16_t>{0, 0}));
}

TEST(BridgeRun, AWriteForAPlcNotConfiguredIsRefusedWithAnAnswer) {
    Rig rig;
    ASSERT_TRUE(rig.ready());
    ASSERT_TRUE(rig.sub.wait_topic("t/press1/status",
                                   [](const json& j) { return j["state"] == "online"; }));
    rig.sub.publish("t/nosuch/write", R"({"id":"n1","tag":"temp","value":1})");
    auto r = response(rig.sub, "n1", "t/nosuch/write/response");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["ok"], false);
    EXPECT_NE((*r)["error"].get<std::string>().find("no PLC named 'nosuch'"), std::string::npos)
        << r->dump();
    // A bad command for it is answered too, with what is wrong with it.
    rig.sub.publish("t/nosuch/write", "[]");
    EXPECT_TRUE(rig.sub.wait_topic("t/nosuch/write/response", [](const json& j) {
        return j["id"] == "" && j["ok"] == false;
    }));
}

TEST(BridgeRun, ATsAheadOfTheClockBeyondTheSkewIsRefused) {
    Rig rig;
    ASSERT_TRUE(rig.ready());
    ASSERT_TRUE(rig.sub.wait_topic("t/press1/status",
                                   [](const json& j) { return j["state"] == "online"; }));
    const auto now = std::chrono::duration_cast<std::chrono::milliseconds>(
                         std::chrono::system_clock::now().time_since_epoch())
                         .count();
    rig.sub.publish("t/press1/write", R"({"id":"f1","tag":"temp","value":4,"ts":)" +
                                          std::to_string(now + 60000) + "}");
    rig.sub.publish("t/press1/write", R"({"id":"f2","tag":"temp","value":5,"ts":)" +
                                          std::to_string(now + 1000) + "}");
    rig.sub.publish("t/press1/write",
                    R"({"id":"f3","tag":"temp","value":6,"ts":-9223372036854775808})");
    rig.sub.publish("t/press1/write",
                    R"({"id":"f4","tag":"temp","value":6,"ts":9223372036854775807})");
    auto far = response(rig.sub, "f1");
    ASSERT_TRUE(far);
    EXPECT_EQ((*far)["ok"], false);
    EXPECT_NE((*far)["error"].get<std::string>().find("ahead of the bridge's clock"),
              std::string::npos)
        << far->dump();
    auto near = response(rig.sub, "f2");  // within ts_skew_s (5 s)
    ASSERT_TRUE(near);
    EXPECT_EQ((*near)["ok"], true) << near->dump();
    for (const char* id : {"f3", "f4"}) {
        auto r = response(rig.sub, id);
        ASSERT_TRUE(r) << id;
        EXPECT_EQ((*r)["ok"], false) << r->dump();
    }
}

TEST(BridgeRun, NumberAndStringIdsAreTwoIdsEchoedWithTheirType) {
    Rig rig;
    ASSERT_TRUE(rig.ready());
    ASSERT_TRUE(rig.sub.wait_topic("t/press1/status",
                                   [](const json& j) { return j["state"] == "online"; }));
    rig.sub.publish("t/press1/write", R"({"id":5,"tag":"temp","value":1.5})");
    auto number = rig.sub.wait_topic("t/press1/write/response",
                                     [](const json& j) { return j["id"] == json(5); });
    ASSERT_TRUE(number);
    rig.sub.publish("t/press1/write", R"({"id":"5","tag":"temp","value":2.5})");
    auto text = response(rig.sub, "5");
    ASSERT_TRUE(text);  // not taken for a repeat of 5
    EXPECT_EQ(number->json()["value"], 1.5);
    EXPECT_EQ((*text)["value"], 2.5);
    auto client = rig.finsd.client();
    ASSERT_TRUE(client);
    EXPECT_EQ(client->read_float(fins::test::addr("D200")).value_or(0), 2.5f);
}

TEST(BridgeRun, EachWritesResponseCarriesItsOwnReadBack) {
    Rig rig;
    ASSERT_TRUE(rig.ready());
    ASSERT_TRUE(rig.sub.wait_topic("t/press1/status",
                                   [](const json& j) { return j["state"] == "online"; }));
    // Published together: they reach the PLC window together (4 frames), yet each read back
    // is taken before the next write to the tag is sent.
    for (int i = 0; i < 12; ++i)
        rig.sub.publish("t/press1/write", R"({"id":"k)" + std::to_string(i) +
                                              R"(","tag":"count","value":)" +
                                              std::to_string(1000 + i) + "}");
    for (int i = 0; i < 12; ++i) {
        auto r = response(rig.sub, "k" + std::to_string(i));
        ASSERT_TRUE(r) << i;
        EXPECT_EQ((*r)["ok"], true) << r->dump();
        EXPECT_EQ((*r)["value"], 1000 + i) << r->dump();
    }
}

TEST(BridgeRun, RetainedCommandsAreRefused) {
    ScratchDir dir{"bridge"};
    Mosquitto broker{dir.path()};
    Finsd finsd{{}};
    ASSERT_TRUE(broker.started() && finsd.started());
    {
        Recorder pub(broker.port(), "none");
        pub.publish("t/press1/write", R"({"id":"r1","tag":"temp","value":9})", 1, true);
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    Recorder sub(broker.port(), "t/#");
    BridgeProcess bridge(dir, mqtt_section(broker.port()) + plc("press1", finsd.port()) + tags);
    auto r = response(sub, "r1");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["ok"], false);
    EXPECT_NE((*r)["error"].get<std::string>().find("retained"), std::string::npos);
    auto client = finsd.client();
    EXPECT_EQ(client->read_float(fins::test::addr("D200")).value_or(-1), 0.0f);
}

TEST(BridgeRun, StoppedPlcIsOfflineWritesFailAtOnceOthersGoOn) {
    ScratchDir dir{"bridge"};
    Mosquitto broker{dir.path()};
    Finsd finsd{{}};
    Recorder sub(broker.port(), "t/#");
    ASSERT_TRUE(broker.started() && finsd.started() && sub.connected());
    const std::uint16_t nobody = free_port();
    BridgeProcess bridge(dir, mqtt_section(broker.port()) + plc("press1", nobody) + tags +
                                  plc("press2", finsd.port()) + tags);
    auto off =
        sub.wait_topic("t/press1/status", [](const json& j) { return j["state"] == "offline"; });
    ASSERT_TRUE(off);
    EXPECT_EQ(off->json()["error"], "no response within the timeout") << off->payload;
    // The cycle that timed out is published with the error, never with values.
    auto failed = sub.wait_topic("t/press1/fast", [](const json&) { return true; });
    ASSERT_TRUE(failed) << bridge.stop().err;
    const json values = failed->json()["values"];
    for (auto& [k, v] : values.items())
        EXPECT_TRUE(v.is_object() && v.contains("error")) << k << " " << v.dump();
    sub.publish("t/press1/write", R"({"id":"o1","tag":"temp","value":1})");
    auto r = response(sub, "o1");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["ok"], false);
    EXPECT_NE((*r)["error"].get<std::string>().find("PLC offline"), std::string::npos) << r->dump();
    EXPECT_TRUE(
        sub.wait_topic("t/press2/fast", [](const json& j) { return j.value("full", false); }));
}

}  // namespace
}  // namespace fins::bridge::test
