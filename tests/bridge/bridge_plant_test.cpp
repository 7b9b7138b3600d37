// fins-bridge on a loopback plant (issue 26 point 15). Without `dest` the bridge addresses
// each PLC as the last number of its IP address (docs/bridge.md), on loopback too: a
// real finsd plant of units at 127.0.64.1-5 (node = last octet, W420 5-2) answers every
// tag of every unit. Before, all of 127/8 was node 1 and units 2-5 answered 0201 on every
// tag while their status said online. A PLC whose every tag fails says so in its status,
// with the hint to set dest.
#include <string>

#include <gtest/gtest.h>

#include "bridge_rig.hpp"

namespace fins::bridge::test {
namespace {

using nlohmann::json;

constexpr int units = 5;

std::string host_of(int n) {
    return "127.0.64." + std::to_string(n);
}

TEST(BridgePlant, EveryLoopbackUnitIsAnsweredWithoutDest) {
    fins::test::FixedPorts lock;
    ScratchDir dir{"bridge-plant"};
    std::string plant = "log_level = \"warn\"\n";
    std::string bridge = "";
    for (int n = 1; n <= units; ++n) {
        plant += "[[plc]]\nname = \"unit-" + std::to_string(n) +
                 "\"\n  [[plc.ethernet]]\n  unit = 0\n  network = 1\n  bind = \"" + host_of(n) +
                 "\"\n  port = 9611\n  [plc.memory]\n  D100 = " + std::to_string(100 + n) + "\n";
        bridge += "[[plc]]\nname = \"u" + std::to_string(n) + "\"\nhost = \"" + host_of(n) +
                  "\"\nport = 9611\ntimeout_ms = 500\n[[plc.group]]\nname = \"g\"\n"
                  "interval_ms = 100\ntags = [ { name = \"speed\", address = \"D100\", "
                  "type = \"int16\" } ]\n";
    }
    Finsd finsd{{"--config", dir.write("plant.toml", plant)}};
    Mosquitto broker{dir.path()};
    Recorder sub(broker.port(), "t/#");
    ASSERT_TRUE(finsd.started() && broker.started() && sub.connected()) << finsd.result().err;
    BridgeProcess process(dir, mqtt_section(broker.port()) + bridge);
    for (int n = 1; n <= units; ++n) {
        const std::string plc = "t/u" + std::to_string(n);
        auto values = sub.wait_topic(plc + "/g", [](const json& j) {
            return j.contains("values") && j["values"]["speed"].is_number();
        });
        ASSERT_TRUE(values) << plc << ": no value\n" << process.stop().err;
        EXPECT_EQ(values->json()["values"]["speed"], 100 + n) << values->payload;
        auto status = sub.wait_topic(plc + "/status", [](const json&) { return true; });
        ASSERT_TRUE(status) << plc;
        EXPECT_EQ(status->json().value("state", ""), "online") << status->payload;
    }
    // No unit's tag carried an error at any time.
    for (const auto& m : sub.messages()) {
        if (m.topic.size() > 2 && m.topic.compare(m.topic.size() - 2, 2, "/g") == 0) {
            EXPECT_EQ(m.payload.find("error"), std::string::npos) << m.topic << " " << m.payload;
        }
    }
}

// finsd is node 12 on 127.0.0.1; the bridge, without dest, addresses node 1 (the last
// number of 127.0.0.1): finsd answers 0201 on every tag. The status is not "online".
TEST(BridgePlant, APlcWhoseEveryTagFailsSaysSoWithTheDestHint) {
    ScratchDir dir{"bridge-failing"};
    Mosquitto broker{dir.path()};
    Finsd finsd{{"--node", "12"}};
    Recorder sub(broker.port(), "t/#");
    ASSERT_TRUE(finsd.started() && broker.started() && sub.connected()) << finsd.result().err;
    BridgeProcess process(dir, mqtt_section(broker.port()) + plc("press1", finsd.port()) + tags);
    auto status = sub.wait_topic("t/press1/status",
                                 [](const json& j) { return j.value("state", "") == "failing"; });
    ASSERT_TRUE(status) << process.stop().err;
    {
        // Retained: a subscriber that comes later is told at once.
        Recorder later(broker.port(), "t/press1/status");
        auto st = later.wait_topic("t/press1/status", [](const json&) { return true; });
        ASSERT_TRUE(st);
        EXPECT_TRUE(st->retain);
        EXPECT_EQ(st->json().value("state", ""), "failing") << st->payload;
    }
    const std::string error = status->json().value("error", "");
    EXPECT_EQ(error.rfind("every tag fails: 0201 destination node not in network", 0), 0u) << error;
    EXPECT_NE(error.find("requests go to node 0.1.0 (the last number of its IP address): if "
                         "the PLC is another node, set dest = \"NET.NODE.UNIT\" for plc "
                         "\"press1\" (`fins --host 127.0.0.1 --port " +
                         std::to_string(finsd.port()) + " probe` tells its node)"),
              std::string::npos)
        << error;
    // Said once: not for every cycle that fails the same way.
    const auto stopped = process.stop();
    std::size_t failing = 0;
    for (const auto& m : sub.messages()) {
        if (m.topic == "t/press1/status" && m.json().value("state", "") == "failing") ++failing;
    }
    EXPECT_EQ(failing, 1u);
    EXPECT_NE(stopped.err.find("PLC press1 failing: every tag fails"), std::string::npos)
        << stopped.err;
}

}  // namespace
}  // namespace fins::bridge::test
