// fins-bridge against a PLC that answers under another FINS node than the one its
// frames go to (docs/bridge.md, "Troubleshooting"). A real finsd is node 12; the bridge
// sends to node 0 (dest = "0.0.0", "the local PLC"), which finsd serves and answers from
// its own address, node 12. Such an answer is not taken for the PLC's (the frame's
// identity check stays), so the frames time out: the PLC's status and the log must say
// why, once, and the stats count the answers.
#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "bridge_rig.hpp"

namespace fins::bridge::test {
namespace {

using nlohmann::json;

const std::string one_tag = R"([[plc.group]]
name = "fast"
interval_ms = 100
tags = [ { name = "speed", address = "D100", type = "int16" } ]
)";

const std::string expected_error =
    R"(answers come from node 12, requests go to node 0 (its dest): set dest = "0.12.0" for plc "press1")";

struct NodeRig {
    ScratchDir dir{"bridge-node"};
    Mosquitto broker{dir.path()};
    Finsd finsd{{"--node", "12"}};
    Recorder sub{broker.port(), "t/#"};
    std::unique_ptr<BridgeProcess> bridge;
    explicit NodeRig(const std::string& dest) {
        bridge = std::make_unique<BridgeProcess>(
            dir, "[bridge]\nstats_s = 1\n" + mqtt_section(broker.port()) +
                     plc("press1", finsd.port(), "dest = \"" + dest + "\"\n") + one_tag);
    }
    bool ready() const { return broker.started() && finsd.started() && sub.connected(); }
};

std::size_t occurrences(const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
        ++n;
    return n;
}

TEST(BridgeNode, AnswersFromAnotherNodeAreCountedAndTheStatusNamesTheDestToSet) {
    NodeRig rig("0.0.0");
    ASSERT_TRUE(rig.ready());
    auto status = rig.sub.wait_topic(
        "t/press1/status", [](const json& j) { return j.value("state", "") == "offline"; });
    ASSERT_TRUE(status);
    EXPECT_EQ(status->json().value("error", ""), expected_error);
    {
        // Retained: a subscriber that comes later is told at once.
        Recorder later(rig.broker.port(), "t/press1/status");
        auto st = later.wait_topic("t/press1/status", [](const json&) { return true; });
        ASSERT_TRUE(st);
        EXPECT_TRUE(st->retain);
        EXPECT_EQ(st->json().value("error", ""), expected_error);
    }

    // The back-off probes are answered from node 12 too, and counted; the status is not
    // published again for each of them.
    auto stats = rig.sub.wait_topic(
        "t/$bridge/test/stats", [](const json& j) { return j.value("other_node_answers", 0) >= 6; },
        std::chrono::seconds(30));
    ASSERT_TRUE(stats);
    EXPECT_EQ(stats->json().value("frames", -1), 0);  // none taken for the PLC's answer

    // The tag carries the timeout, never a value from the other node's answer.
    for (const auto& m : rig.sub.messages())
        if (m.topic == "t/press1/fast") {
            const auto speed = m.json()["values"]["speed"];
            EXPECT_TRUE(speed.is_object() && speed.contains("error")) << m.payload;
        }

    const auto messages = rig.sub.messages();
    const auto statuses = std::count_if(messages.begin(), messages.end(), [](const Received& m) {
        return m.topic == "t/press1/status";
    });
    EXPECT_EQ(statuses, 1) << "one status, not one per probe";
    const auto stopped = rig.bridge->stop();
    EXPECT_EQ(stopped.exit_code, 0) << stopped.err;
    EXPECT_EQ(occurrences(stopped.err, expected_error), 1u) << stopped.err;
}

// The dest the status names is the one that works.
TEST(BridgeNode, TheDestTheStatusNamesPollsThePlc) {
    NodeRig rig("0.12.0");
    ASSERT_TRUE(rig.ready());
    ASSERT_TRUE(rig.sub.wait_topic("t/press1/status",
                                   [](const json& j) { return j.value("state", "") == "online"; }));
    ClientOptions o;
    o.port = rig.finsd.port();
    o.destination = {0, 12, 0};
    auto client = Client::connect(o);
    ASSERT_TRUE(client) << client.error().message();
    ASSERT_TRUE((*client)->write_words(fins::test::addr("D100"), std::vector<std::uint16_t>{42}));
    EXPECT_TRUE(rig.sub.wait_topic(
        "t/press1/fast", [](const json& j) { return j["values"].value("speed", 0) == 42; }));
}

}  // namespace
}  // namespace fins::bridge::test
