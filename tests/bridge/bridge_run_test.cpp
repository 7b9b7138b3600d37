// fins-bridge end to end: real finsd PLCs, a real mosquitto, the fins-bridge binary and a
// libmosquitto subscriber (bridge_fixture.hpp).
#include <gtest/gtest.h>

#include "bridge_rig.hpp"

namespace fins::bridge::test {
namespace {

using nlohmann::json;

TEST(BridgeRun, PublishesStatusSnapshotAndThenOnlyChanges) {
    Rig rig;
    ASSERT_TRUE(rig.ready());
    auto status =
        rig.sub.wait_topic("t/press1/status", [](const json& j) { return j["state"] == "online"; });
    ASSERT_TRUE(status);
    ASSERT_TRUE(rig.sub.wait_topic("t/$bridge/test/status",
                                   [](const json& j) { return j["state"] == "online"; }));
    {
        // Both statuses are retained: a subscriber that comes later gets them at once.
        Recorder later(rig.broker.port(), "t/+/status");
        auto st = later.wait_topic("t/press1/status",
                                   [](const json& j) { return j["state"] == "online"; });
        ASSERT_TRUE(st);
        EXPECT_TRUE(st->retain);
        Recorder later2(rig.broker.port(), "t/$bridge/+/status");
        auto me = later2.wait_topic("t/$bridge/test/status",
                                    [](const json& j) { return j["state"] == "online"; });
        ASSERT_TRUE(me);
        EXPECT_TRUE(me->retain);
    }
    auto full =
        rig.sub.wait_topic("t/press1/fast", [](const json& j) { return j.value("full", false); });
    ASSERT_TRUE(full);
    const json v = full->json()["values"];
    EXPECT_EQ(
        v, json::parse(
               R"({"speed":0,"run":false,"temp":0,"count":0,"recipe":"","far":0,"done":false})"));
    EXPECT_GT(full->json()["ts"].get<std::int64_t>(), 1700000000000);

    auto client = rig.finsd.client();
    ASSERT_TRUE(client);
    const auto before = rig.sub.count();
    ASSERT_TRUE(client->write_words(fins::test::addr("D100"), std::vector<std::uint16_t>{0xFFFE}));
    ASSERT_TRUE(client->write_words(fins::test::addr("D5000"), std::vector<std::uint16_t>{77}));
    auto change = rig.sub.wait_topic(
        "t/press1/fast", [](const json& j) { return j["values"].contains("far"); },
        std::chrono::seconds(15), before);
    ASSERT_TRUE(change);
    EXPECT_FALSE(change->json().contains("full"));
    // Only what changed: speed (written first, maybe in an earlier message) and far.
    const json changed = change->json()["values"];
    for (auto& [k, val] : changed.items())
        EXPECT_TRUE(k == "speed" || k == "far") << k;
    auto speed = rig.sub.wait_topic(
        "t/press1/fast", [](const json& j) { return j["values"].value("speed", 0) == -2; },
        std::chrono::seconds(15), before);
    EXPECT_TRUE(speed);
    EXPECT_EQ(change->json()["values"]["far"], 77);
}

// kill -9: nothing can publish the PLC's status offline, so its retained "online" stays.
// It names its owner, and the owner's retained status (the Will) says offline: together
// they tell a consumer that nobody polls the PLC (docs/bridge.md, "Topics and payloads").
TEST(BridgeRun, AKilledBridgesPlcStatusNamesItsOwnerWhoseStatusSaysOffline) {
    Rig rig;
    ASSERT_TRUE(rig.ready());
    auto status =
        rig.sub.wait_topic("t/press1/status", [](const json& j) { return j["state"] == "online"; });
    ASSERT_TRUE(status);
    EXPECT_EQ(status->json()["instance"], "test");
    rig.bridge->stop(SIGKILL);
    Recorder later(rig.broker.port(), "t/#");
    ASSERT_TRUE(later.connected());
    auto owner = later.wait_topic("t/$bridge/test/status",
                                  [](const json& j) { return j["state"] == "offline"; });
    ASSERT_TRUE(owner);
    EXPECT_TRUE(owner->retain);
    auto stale = later.wait_topic("t/press1/status", [](const json&) { return true; });
    ASSERT_TRUE(stale);
    EXPECT_TRUE(stale->retain);
    EXPECT_EQ(stale->json()["state"], "online");
    EXPECT_EQ(stale->json()["instance"], "test");
}

TEST(BridgeRun, EndCodesAreCarriedPerTag) {
    ScratchDir dir{"bridge"};
    Mosquitto broker{dir.path()};
    // A CJ1M has no EM (1101 area missing) and refuses network writes (protected).
    Finsd finsd{{"--profile", "cj1m", "--network-write-protection", "all"}};
    Recorder sub(broker.port(), "t/#");
    ASSERT_TRUE(broker.started() && finsd.started() && sub.connected());
    BridgeProcess bridge(
        dir, mqtt_section(broker.port()) + plc("press1", finsd.port()) + R"([[plc.group]]
name = "g"
interval_ms = 100
tags = [ { name = "ok", address = "D100", type = "int16", writable = true },
         { name = "ok2", address = "D101", type = "int16" },
         { name = "em", address = "E0_100", type = "int16" },
         { name = "em2", address = "E0_101", type = "int16" } ]
)");
    auto m = sub.wait_topic("t/press1/g", [](const json& j) { return j.value("full", false); });
    ASSERT_TRUE(m);
    const json v = m->json()["values"];
    EXPECT_EQ(v["ok"], 0);
    ASSERT_TRUE(v["em"].is_object()) << v.dump();
    EXPECT_EQ(v["em"]["end_code"], "1101") << v.dump();
    EXPECT_NE(v["em"]["error"].get<std::string>().find("1101"), std::string::npos);
    auto st = sub.wait_topic("t/press1/status", [](const json&) { return true; });
    ASSERT_TRUE(st);
    EXPECT_EQ(st->json()["state"], "online");  // an end code is an answer
    sub.publish("t/press1/write", R"({"id":"p1","tag":"ok","value":3})");
    auto r = response(sub, "p1");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["ok"], false) << r->dump();
    EXPECT_TRUE((*r)["end_code"].is_string()) << r->dump();
    EXPECT_NE((*r)["end_code"], "0000");
}

TEST(BridgeRun, FinsTcp) {
    Rig rig("transport = \"tcp\"\n");
    ASSERT_TRUE(rig.ready());
    ASSERT_TRUE(rig.sub.wait_topic("t/press1/status",
                                   [](const json& j) { return j["state"] == "online"; }));
    auto client = rig.finsd.client();
    ASSERT_TRUE(client->write_words(fins::test::addr("D100"), std::vector<std::uint16_t>{321}));
    EXPECT_TRUE(rig.sub.wait_topic(
        "t/press1/fast", [](const json& j) { return j["values"].value("speed", 0) == 321; }));
    rig.sub.publish("t/press1/write", R"({"id":"t1","tag":"temp","value":-5})");
    auto r = response(rig.sub, "t1");
    ASSERT_TRUE(r);
    EXPECT_EQ((*r)["value"], -5.0) << r->dump();
}

TEST(BridgeRun, TlsAndPasswordBroker) {
    ScratchDir dir{"bridge"};
    ASSERT_TRUE(make_tls(dir)) << "openssl failed";
    const std::string d = dir.path().string();
    ASSERT_EQ(shell("mosquitto_passwd -b -c " + d + "/passwd bridge s3cret && chmod 0644 " + d +
                    "/passwd"),
              0);
    Mosquitto broker{dir.path(), "cafile " + d + "/ca.crt\ncertfile " + d +
                                     "/server.crt\nkeyfile " + d + "/server.key\npassword_file " +
                                     d + "/passwd\n"};
    Finsd finsd{{}};
    ASSERT_TRUE(broker.started() && finsd.started());
    Recorder sub(broker.port(), "t/#", {d + "/ca.crt", "bridge", "s3cret", ""});
    ASSERT_TRUE(sub.connected());
    BridgeProcess bridge(dir, mqtt_section(broker.port(), "ca_file = \"" + d +
                                                              "/ca.crt\"\nusername = \"bridge\"\n"
                                                              "password = \"s3cret\"\n") +
                                  plc("press1", finsd.port()) + tags);
    EXPECT_TRUE(sub.wait_topic("t/press1/fast", [](const json& j) {
        return j.value("full", false);
    })) << bridge.stop().err;
    // A wrong password is refused by the broker: nothing is published.
    Recorder wrong(broker.port(), "t/#", {d + "/ca.crt", "bridge", "wrong", ""});
    EXPECT_FALSE(wrong.connected());
}

TEST(BridgeRun, SecondBrokerIsTriedWhenTheFirstIsDown) {
    ScratchDir dir{"bridge"};
    Mosquitto broker{dir.path()};
    Finsd finsd{{}};
    Recorder sub(broker.port(), "t/#");
    ASSERT_TRUE(broker.started() && finsd.started() && sub.connected());
    const auto down = free_port();
    BridgeProcess bridge(
        dir, "[mqtt]\nhosts = [\"127.0.0.1:" + std::to_string(down) +
                 "\", \"127.0.0.1:" + std::to_string(broker.port()) +
                 "\"]\ntopic_prefix = \"t\"\nbackoff_min_ms = 50\nbackoff_max_ms = 200\n" +
                 plc("press1", finsd.port()) + tags);
    EXPECT_TRUE(sub.wait_topic("t/press1/fast", [](const json& j) {
        return j.value("full", false);
    })) << bridge.stop().err;
}

TEST(BridgeRun, GracefulStopPublishesOfflineKillLeavesTheWill) {
    Rig rig;
    ASSERT_TRUE(rig.ready());
    ASSERT_TRUE(rig.sub.wait_topic("t/$bridge/test/status",
                                   [](const json& j) { return j["state"] == "online"; }));
    auto from = rig.sub.count();
    auto r = rig.bridge->stop(SIGTERM);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_TRUE(rig.sub.wait_topic(
        "t/$bridge/test/status", [](const json& j) { return j["state"] == "offline"; },
        std::chrono::seconds(10), from));
    BridgeProcess again(rig.dir, mqtt_section(rig.broker.port(), "keepalive_s = 5\n") +
                                     plc("press1", rig.finsd.port()) + tags);
    from = rig.sub.count();
    ASSERT_TRUE(rig.sub.wait_topic(
        "t/$bridge/test/status", [](const json& j) { return j["state"] == "online"; },
        std::chrono::seconds(10), from));
    from = rig.sub.count();
    again.stop(SIGKILL);
    // The broker publishes the Will when it notices the dead connection (closed socket: at once).
    EXPECT_TRUE(rig.sub.wait_topic(
        "t/$bridge/test/status", [](const json& j) { return j["state"] == "offline"; },
        std::chrono::seconds(20), from));
}

TEST(BridgeRun, BadConfigStopsAtStartWithItsPosition) {
    ScratchDir dir{"bridge"};
    const auto file = dir.write("bad.toml",
                                "[mqtt]\nhost = \"127.0.0.1\"\n[[plc]]\nname = \"a\"\n"
                                "host = \"h\"\n[[plc.group]]\nname = \"g\"\n"
                                "tags = [{name=\"x\", address=\"D40000\", type=\"int16\"}]\n");
    auto r = fins::test::run({bridge_path, "--config", file});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err.rfind("fins-bridge: " + file + ":8:", 0), 0u) << r.err;
    // min above max, an empty host, a CA file that is not there: the same, at their key.
    const auto range =
        dir.write("range.toml",
                  "[[plc]]\nname = \"a\"\nhost = \"h\"\n[[plc.group]]\nname = \"g\"\n"
                  "tags = [{name=\"x\", address=\"D0\", type=\"int16\", min=3, max=1}]\n");
    r = fins::test::run({bridge_path, "--config", range});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err.rfind("fins-bridge: " + range + ":6:", 0), 0u) << r.err;
    const auto ca = dir.write("ca.toml",
                              "[mqtt]\nca_file = \"/nonexistent/ca.crt\"\n[[plc]]\n"
                              "name = \"a\"\nhost = \"\"\n");
    r = fins::test::run({bridge_path, "--config", ca});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_EQ(r.err.rfind("fins-bridge: " + ca + ":2:11: ca_file", 0), 0u) << r.err;
    auto missing = fins::test::run({bridge_path, "--config", dir.path().string() + "/none.toml"});
    EXPECT_EQ(missing.exit_code, 2);
    auto usage = fins::test::run({bridge_path});
    EXPECT_EQ(usage.exit_code, 2);
    auto plan =
        fins::test::run({bridge_path, "--config",
                         std::string(FINS_SOURCE_DIR) + "/packaging/fins-bridge.toml", "--plan"});
    EXPECT_EQ(plan.exit_code, 0) << plan.err;
    EXPECT_NE(plan.out.find("press1/fast: 3 tags, 1 frames every 100 ms"), std::string::npos)
        << plan.out;
}

}  // namespace
}  // namespace fins::bridge::test

namespace fins::bridge::test {
namespace {

// A PLC behind a router: the bridge talks to router-a (network 1) and addresses line-2
// (network 2, node 5) with dest = "2.5.0"; router-a relays over its second unit.
TEST(BridgeRun, PlcBehindARouter) {
    fins::test::FixedPorts lock;
    ScratchDir dir{"bridge"};
    const auto plant = dir.write("plant.toml", R"(log_level = "warn"
[[plc]]
name = "router-a"
  [[plc.ethernet]]
  unit = 0
  network = 1
  bind = "127.0.61.1"
  port = 9611
  [[plc.ethernet]]
  unit = 1
  network = 2
  bind = "127.0.62.1"
  port = 9611
[[plc]]
name = "line-2"
  [[plc.ethernet]]
  unit = 0
  network = 2
  bind = "127.0.62.5"
  port = 9611
  [[plc.relay]]
  network = 1
  via_network = 2
  via_node = 1
)");
    Finsd finsd{{"--config", plant}};
    Mosquitto broker{dir.path()};
    Recorder sub(broker.port(), "t/#");
    ASSERT_TRUE(finsd.started() && broker.started() && sub.connected()) << finsd.result().err;
    BridgeProcess bridge(dir, mqtt_section(broker.port()) +
                                  "[[plc]]\nname = \"line2\"\nhost = \"127.0.61.1\"\nport = 9611\n"
                                  "dest = \"2.5.0\"\ntimeout_ms = 500\n" +
                                  tags);
    auto full =
        sub.wait_topic("t/line2/fast", [](const json& j) { return j.value("full", false); });
    ASSERT_TRUE(full) << bridge.stop().err;
    EXPECT_EQ(full->json()["values"]["speed"], 0) << full->payload;
    sub.publish("t/line2/write", R"({"id":"r1","tag":"temp","value":12.25})");
    auto r =
        sub.wait_topic("t/line2/write/response", [](const json& j) { return j["id"] == "r1"; });
    ASSERT_TRUE(r);
    EXPECT_EQ(r->json()["value"], 12.25) << r->payload;
    // The value is in line-2, not in router-a.
    ClientOptions o;  // through router-a, as the bridge does
    o.host = "127.0.61.1";
    o.port = 9611;
    o.destination = {2, 5, 0};
    auto line = Client::connect(o);
    ASSERT_TRUE(line);
    EXPECT_EQ((*line)->read_float(fins::test::addr("D200")).value_or(0), 12.25f);
    ClientOptions a;
    a.host = "127.0.61.1";
    a.port = 9611;
    auto router = Client::connect(a);
    ASSERT_TRUE(router);
    EXPECT_EQ((*router)->read_float(fins::test::addr("D200")).value_or(-1), 0.0f);
}

}  // namespace
}  // namespace fins::bridge::test
