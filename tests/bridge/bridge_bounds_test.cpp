// The bridge's memory for what a peer controls is bounded (docs/bridge.md "Bounds"): the
// PLC name of a write comes from its topic and the id from its payload, so ids are
// remembered only for configured PLCs, at most [write] id_memory each, and commands that
// wait for this instance to join are at most max_pending_commands. No broker, no PLC: the
// Bridge is driven through incoming() and its io_context.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "bridge/bridge.hpp"
#include "bridge/cluster/cluster_ownership.hpp"
#include "bridge/json_payload.hpp"
#include "bridge_test_support.hpp"

namespace fins::bridge {
namespace {

BridgeConfig small_config() {
    // Port 9: nothing polls it here (the pollers are never started in the first test).
    auto c = test::parse_ok(
        "[[plc]]\nname = \"p\"\nhost = \"127.0.0.1\"\nport = 9\n[[plc.group]]\nname = \"g\"\n"
        "tags = [{name=\"a\",address=\"D0\",type=\"int16\",writable=true}]\n");
    c.write.id_memory = 8;
    c.mqtt.topic_prefix = "finskit";
    return c;
}

// Hands `n` messages to the bridge, letting its io_context take them in batches below the
// bound of commands not yet handled.
void feed(asio::io_context& io, Bridge& b, int n,
          const std::function<std::pair<std::string, std::string>(int)>& message) {
    for (int i = 0; i < n; ++i) {
        auto [topic, payload] = message(i);
        b.incoming(std::move(topic), std::move(payload), false);
        if (i % 500 == 499) {
            io.restart();
            io.poll();
        }
    }
    io.restart();
    io.poll();
}

TEST(BridgeBounds, IdsAreRememberedOnlyForConfiguredPlcsAndAtMostIdMemoryEach) {
    const auto config = small_config();
    asio::io_context io;
    Bridge b(io, config, std::make_unique<JsonPayload>("finskit", "test"),
             std::make_unique<SingleInstance>());
    // Writes for 5,000 PLC names the configuration does not have: refused, nothing kept.
    feed(io, b, 5000, [](int i) {
        return std::pair{"finskit/x" + std::to_string(i) + "/write",
                         R"({"id":"a)" + std::to_string(i) + R"(","tag":"a","value":1})"};
    });
    EXPECT_EQ(b.remembered_plcs(), 0u);
    EXPECT_EQ(b.remembered_ids(), 0u);
    // 5,000 ids for the configured PLC (refused: it is not polled here): the last 8 kept.
    feed(io, b, 5000, [](int i) {
        return std::pair{std::string("finskit/p/write"),
                         R"({"id":)" + std::to_string(i) + R"(,"tag":"a","value":1})"};
    });
    EXPECT_EQ(b.remembered_plcs(), 1u);
    EXPECT_EQ(b.remembered_ids(), 8u);
    EXPECT_EQ(b.dropped_commands(), 0u);
}

TEST(BridgeBounds, CommandsWaitingForTheJoinAreBounded) {
    const auto config = small_config();
    asio::io_context io;
    Bridge b(io, config, std::make_unique<JsonPayload>("finskit", "test"),
             std::make_unique<cluster::ClusterOwnership>("test", "finskit"));
    feed(io, b, 3000, [](int i) {
        return std::pair{"finskit/x" + std::to_string(i) + "/write",
                         R"({"id":"a)" + std::to_string(i) + R"(","tag":"a","value":1})"};
    });
    EXPECT_EQ(b.held_commands(), max_pending_commands);
    EXPECT_EQ(b.dropped_commands(), 3000u - max_pending_commands);
    // Its own status comes back: joined, the held commands are handled (refused: unknown
    // PLCs) and nothing is remembered for them.
    feed(io, b, 1, [](int) {
        return std::pair{std::string("finskit/$bridge/test/status"),
                         std::string(R"({"state":"online","instance":"test"})")};
    });
    EXPECT_EQ(b.held_commands(), 0u);
    EXPECT_EQ(b.remembered_plcs(), 0u);
    b.stop();
}

}  // namespace
}  // namespace fins::bridge
