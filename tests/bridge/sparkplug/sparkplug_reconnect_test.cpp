// Sparkplug's session across reconnects (issue 27): the births of a connection run inside its
// CONNACK on the bridge's one thread, so nothing of the Edge Node goes out on a connection
// before that connection's NBIRTH, and seq counts on from it without a gap. The session is
// taken over (another client with its client id) again and again while DDATA flows at 50 a
// second; the subscriber checks every message of the Edge Node in the broker's order.
#include <gtest/gtest.h>

#include "bridge/cluster/processes.hpp"
#include "integration/support/finsd_process.hpp"
#include "sparkplug_b.pb.h"

namespace tb = fins::test::bridge;
namespace pb = finskit::sparkplug::pb;
using namespace std::chrono_literals;

namespace {

struct Decoded {
    std::string verb;
    pb::Payload payload;
};

// The Edge Node edge-1's messages (spBv1.0/plant/VERB/edge-1[/device]).
std::vector<Decoded> edge_node_messages(const std::vector<tb::Received>& ms) {
    const std::string prefix = "spBv1.0/plant/";
    std::vector<Decoded> out;
    for (const auto& m : ms) {
        if (m.topic.rfind(prefix, 0) != 0) continue;
        const auto rest = m.topic.substr(prefix.size());  // VERB/edge-1[/device]
        const auto a = rest.find('/');
        if (a == std::string::npos) continue;
        const auto b = rest.find('/', a + 1);
        if (rest.substr(a + 1, b == std::string::npos ? b : b - a - 1) != "edge-1") continue;
        Decoded d;
        d.verb = rest.substr(0, a);
        EXPECT_TRUE(d.payload.ParseFromString(m.payload)) << m.topic;
        out.push_back(std::move(d));
    }
    return out;
}

std::size_t births(const std::vector<tb::Received>& ms, std::size_t from = 0) {
    std::size_t n = 0;
    const auto ds = edge_node_messages({ms.begin() + static_cast<std::ptrdiff_t>(from), ms.end()});
    for (const auto& d : ds)
        n += d.verb == "NBIRTH" ? 1U : 0U;
    return n;
}

std::int64_t bdseq_of(const pb::Payload& p) {
    for (const auto& m : p.metrics())
        if (m.name() == "bdSeq") return static_cast<std::int64_t>(m.long_value());
    return -1;
}

}  // namespace

TEST(SparkplugReconnect, NothingBeforeEachConnectionsNbirthAndSeqCountsOnFromIt) {
    const std::string kicker = "/usr/bin/mosquitto_pub";
    if (tb::mosquitto_path().empty() || !tb::have_program(kicker))
        GTEST_SKIP() << "mosquitto or mosquitto_pub is not installed";
    fins::test::ScratchDir dir("sparkplug-reconnect");
    tb::Mosquitto broker(dir.path());
    ASSERT_TRUE(broker.started());
    fins::test::Finsd finsd({});
    ASSERT_TRUE(finsd.started());
    tb::CountingRelay relay(1, finsd.port());
    const std::string conf =
        "[bridge]\ninstance = \"edge-1\"\npayload = \"sparkplug\"\n"
        "[mqtt]\nhost = \"127.0.0.1\"\nport = " +
        std::to_string(broker.port()) +
        "\ntopic_prefix = \"plant\"\nbackoff_min_ms = 50\nbackoff_max_ms = 200\n"
        "[[plc]]\nname = \"press1\"\nhost = \"127.0.0.1\"\nport = " +
        std::to_string(relay.port(0)) +
        "\n[[plc.group]]\nname = \"fast\"\ninterval_ms = 20\npublish = \"always\"\n"
        "tags = [ { name = \"speed\", address = \"D100\", type = \"int16\" } ]\n";
    const auto conf_path = dir.write("bridge.toml", conf);
    tb::Recorder rec(broker.port(), std::vector<std::string>{"spBv1.0/#"});
    ASSERT_TRUE(rec.connected());
    tb::Child bridge({tb::bridge_path, "--config", conf_path}, dir.path() / "bridge.log");
    ASSERT_TRUE(rec.wait([](const auto& ms) { return births(ms) >= 1; }, 30s)) << bridge.log();

    // Five takeovers of the session, each once DDATA flows on the connection before it.
    constexpr int kicks = 5;
    for (int k = 0; k < kicks; ++k) {
        const auto from = rec.count();
        ASSERT_TRUE(rec.wait(
            [&](const auto& ms) {
                return edge_node_messages(
                           {ms.begin() + static_cast<std::ptrdiff_t>(from), ms.end()})
                           .size() >= 20;
            },
            15s))
            << bridge.log();
        const auto before = rec.count();
        const auto cmd = kicker + " -h 127.0.0.1 -p " + std::to_string(broker.port()) +
                         " -i fins-bridge-edge-1-session -t plant/kick -m x >/dev/null 2>&1";
        (void)std::system(cmd.c_str());  // it may itself be taken over by the bridge: no matter
        ASSERT_TRUE(rec.wait([&](const auto& ms) { return births(ms, before) >= 1; }, 15s))
            << bridge.log();
    }
    ASSERT_TRUE(rec.wait([](const auto& ms) { return births(ms) >= kicks + 1; }, 15s));

    // Every message in order: DBIRTH/DDATA only after the NBIRTH of its connection, seq + 1
    // from it, bdSeq + 1 per connection.
    const auto ds = edge_node_messages(rec.messages());
    bool born = false;
    std::uint64_t expected = 0;
    std::int64_t last_bdseq = -1;
    std::size_t nbirths = 0;
    for (std::size_t i = 0; i < ds.size(); ++i) {
        const auto& d = ds[i];
        if (d.verb == "NDEATH") {
            born = false;
        } else if (d.verb == "NBIRTH") {
            EXPECT_EQ(d.payload.seq(), 0u) << "message " << i;
            const auto bd = bdseq_of(d.payload);
            if (last_bdseq >= 0) {
                EXPECT_EQ(bd, (last_bdseq + 1) % 256) << "message " << i;
            }
            last_bdseq = bd;
            born = true;
            expected = 1;
            ++nbirths;
        } else if (d.verb == "DBIRTH" || d.verb == "DDATA" || d.verb == "DDEATH") {
            ASSERT_TRUE(born) << d.verb << " before the NBIRTH of its connection, message " << i;
            ASSERT_EQ(d.payload.seq(), expected) << d.verb << ", message " << i;
            expected = (expected + 1) % 256;
        }
    }
    EXPECT_GE(nbirths, static_cast<std::size_t>(kicks + 1));
    EXPECT_TRUE(bridge.running()) << bridge.log();
}
