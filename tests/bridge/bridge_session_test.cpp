// Writes the broker accepted are answered (docs/bridge.md "Writes"): the bridge's MQTT
// session is persistent, so QoS 1 commands published while it is stopped, or while it
// reconnects to a restarted broker with persistence, are delivered when it is back, and
// each gets exactly one response: executed, or refused by its ttl_s.
#include <gtest/gtest.h>

#include <unistd.h>

#include <map>
#include <set>
#include <string>
#include <utility>

#include "bridge_rig.hpp"

namespace fins::bridge::test {
namespace {

using nlohmann::json;

std::int64_t now_ms() {
    return std::chrono::duration_cast<std::chrono::milliseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
}

// Responses on `topic` by the id's JSON text ("\"w1\"", "5"): how many, and the first.
// A response the broker delivers to the recorder again (same message id and payload: the
// recorder's PUBACK did not reach a broker that stopped) is one response, counted once.
struct Answers {
    std::map<std::string, std::size_t> count;
    std::map<std::string, json> first;
};
Answers answers(const std::vector<Received>& ms, const std::string& topic) {
    Answers a;
    std::set<std::pair<int, std::string>> seen;
    for (const auto& m : ms) {
        if (m.topic != topic || !seen.insert({m.mid, m.payload}).second) continue;
        const auto j = m.json();
        if (!j.is_object() || !j.contains("id")) continue;
        const auto key = j["id"].dump();
        if (a.count[key]++ == 0) a.first[key] = j;
    }
    return a;
}

// Waits until every id in `ids` (JSON texts) has an answer on `topic`.
bool all_answered(Recorder& sub, const std::string& topic, const std::vector<std::string>& ids,
                  std::chrono::seconds timeout = std::chrono::seconds(60)) {
    return sub.wait(
        [&](const std::vector<Received>& ms) {
            const auto a = answers(ms, topic);
            for (const auto& id : ids)
                if (a.count.find(id) == a.count.end()) return false;
            return true;
        },
        timeout);
}

constexpr const char* response_topic = "t/press1/write/response";

TEST(BridgeSession, WritesPublishedWhileTheBridgeIsStoppedAreAnsweredOnceWhenItStarts) {
    ScratchDir dir{"bridge"};
    Mosquitto broker{dir.path()};
    fins::test::Finsd finsd{{}};
    Recorder sub{broker.port(), "t/#"};
    ASSERT_TRUE(broker.started() && finsd.started() && sub.connected());
    const auto config = mqtt_section(broker.port()) + plc("press1", finsd.port()) + tags;
    auto bridge = std::make_unique<BridgeProcess>(dir, config);
    ASSERT_TRUE(
        sub.wait_topic("t/press1/status", [](const json& j) { return j["state"] == "online"; }));
    auto from = sub.count();
    bridge->stop();
    ASSERT_TRUE(sub.wait_topic(
        "t/$bridge/test/status", [](const json& j) { return j["state"] == "offline"; },
        std::chrono::seconds(15), from));

    // While it is stopped: fresh writes, writes older than ttl_s (10 s), and 7 and "7".
    std::vector<std::string> fresh;
    std::vector<std::string> old;
    const auto stale = std::to_string(now_ms() - 60000);
    for (int i = 0; i < 24; ++i) {
        const auto id = "r" + std::to_string(i);
        const auto value = std::to_string(i + 1);
        if (i % 2 == 0) {
            sub.publish("t/press1/write",
                        R"({"id":")" + id + R"(","tag":"count","value":)" + value + "}");
            fresh.push_back(json(id).dump());
        } else {
            sub.publish("t/press1/write", R"({"id":")" + id + R"(","tag":"count","value":)" +
                                              value + R"(,"ts":)" + stale + "}");
            old.push_back(json(id).dump());
        }
    }
    sub.publish("t/press1/write", R"({"id":7,"tag":"temp","value":1.5})");
    sub.publish("t/press1/write", R"({"id":"7","tag":"temp","value":2.5})");
    fresh.push_back("7");
    fresh.push_back("\"7\"");

    from = sub.count();
    bridge = std::make_unique<BridgeProcess>(dir, config);
    auto ids = fresh;
    ids.insert(ids.end(), old.begin(), old.end());
    ASSERT_TRUE(all_answered(sub, response_topic, ids)) << bridge->stop().err;
    // A last write, answered after all the others: a second answer to any would be there.
    sub.publish("t/press1/write", R"({"id":"last","tag":"speed","value":1})");
    ASSERT_TRUE(all_answered(sub, response_topic, {"\"last\""}));

    const auto a = answers(sub.messages(), response_topic);
    for (const auto& id : fresh) {
        EXPECT_EQ(a.count.at(id), 1u) << id;
        EXPECT_EQ(a.first.at(id)["ok"], true) << a.first.at(id).dump();
    }
    for (const auto& id : old) {
        EXPECT_EQ(a.count.at(id), 1u) << id;
        EXPECT_EQ(a.first.at(id)["ok"], false) << a.first.at(id).dump();
        EXPECT_NE(a.first.at(id)["error"].get<std::string>().find("older than the TTL"),
                  std::string::npos)
            << a.first.at(id).dump();
    }
    // 7 and "7" are two writes, each answered with its own id and its own read back, in order.
    EXPECT_EQ(a.first.at("7")["value"], 1.5);
    EXPECT_EQ(a.first.at("\"7\"")["value"], 2.5);
    auto client = finsd.client();
    ASSERT_TRUE(client);
    EXPECT_EQ(client->read_float(fins::test::addr("D200")).value_or(0), 2.5f);
    // The writes ran in the order they were published: the last fresh one is the value.
    EXPECT_EQ(a.first.at("\"r22\"")["value"], 23);
}

TEST(BridgeSession, WritesAroundARestartOfABrokerWithPersistenceAreEachAnsweredOnce) {
    ScratchDir dir{"bridge"};
    Mosquitto broker{dir.path(), "", true};
    fins::test::Finsd finsd{{}};
    Recorder::Options o;
    o.persistent_id = "session-test-" + std::to_string(::getpid());
    Recorder sub{broker.port(), std::vector<std::string>{"t/#"}, o};
    ASSERT_TRUE(broker.started() && finsd.started() && sub.connected());
    const auto config = mqtt_section(broker.port()) + plc("press1", finsd.port()) + tags;
    auto bridge = std::make_unique<BridgeProcess>(dir, config);
    ASSERT_TRUE(
        sub.wait_topic("t/press1/status", [](const json& j) { return j["state"] == "online"; }));

    std::vector<std::string> ids;
    int n = 0;
    const auto send = [&](int count) {
        for (int i = 0; i < count; ++i, ++n) {
            const auto id = "b" + std::to_string(n);
            sub.publish("t/press1/write", R"({"id":")" + id + R"(","tag":"count","value":)" +
                                              std::to_string(n) + "}");
            ids.push_back(json(id).dump());
        }
    };
    // The broker restarts while the bridge runs: before, while it is down (queued by the
    // sender's client) and after.
    send(100);
    ASSERT_TRUE(all_answered(sub, response_topic, ids));
    broker.stop();
    send(100);
    ASSERT_TRUE(broker.restart());
    send(100);
    ASSERT_TRUE(all_answered(sub, response_topic, ids)) << bridge->stop().err;

    // The bridge is stopped, the broker restarts from its database, writes are published:
    // the bridge's session (its subscription and the queued writes) outlived both.
    auto from = sub.count();
    bridge->stop();
    ASSERT_TRUE(sub.wait_topic(
        "t/$bridge/test/status", [](const json& j) { return j["state"] == "offline"; },
        std::chrono::seconds(15), from));
    ASSERT_TRUE(broker.restart());
    from = sub.count();
    sub.publish("t/marker", "{}");  // the sender is connected again once this comes back
    ASSERT_TRUE(sub.wait_for([](const Received& r) { return r.topic == "t/marker"; },
                             std::chrono::seconds(15), from));
    send(10);
    bridge = std::make_unique<BridgeProcess>(dir, config);
    ASSERT_TRUE(all_answered(sub, response_topic, ids)) << bridge->stop().err;

    sub.publish("t/press1/write", R"({"id":"last","tag":"speed","value":1})");
    ASSERT_TRUE(all_answered(sub, response_topic, {"\"last\""}));
    const auto a = answers(sub.messages(), response_topic);
    std::size_t executed = 0;
    for (const auto& id : ids) {
        EXPECT_EQ(a.count.at(id), 1u) << id << " " << a.first.at(id).dump();
        if (a.first.at(id)["ok"] == true) ++executed;
    }
    // Refused ones say why (16 writes already waiting ...): none is lost in silence.
    EXPECT_GT(executed, 0u);
}

}  // namespace
}  // namespace fins::bridge::test
