// Several fins-bridge processes share one PLC list through one mosquitto (docs/bridge.md
// "Several instances"). Real parts only: finsd, mosquitto, fins-bridge processes, and a UDP
// relay per PLC in front of finsd that counts which sender polls it and how many MEMORY AREA
// WRITEs pass. Shown: while membership is stable each PLC is polled by exactly one instance;
// after kill -9 of one, every PLC keeps publishing and is again polled by exactly one; a write
// is executed once, by the owner, before and after the kill.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "bridge/cluster/processes.hpp"
#include "bridge/cluster/rendezvous.hpp"
#include "integration/support/finsd_process.hpp"

namespace tb = fins::test::bridge;
using namespace std::chrono_literals;

namespace {

constexpr int plc_count = 8;
const std::string prefix = "fleet";

std::string plc_name(int i) {
    return "press" + std::to_string(i);
}

std::string config_text(const tb::CountingRelay& relay, std::uint16_t mqtt_port) {
    std::string c = "[bridge]\nfailover_s = 10\n[mqtt]\nhost = \"127.0.0.1\"\nport = " +
                    std::to_string(mqtt_port) + "\ntopic_prefix = \"" + prefix + "\"\n";
    for (int i = 0; i < plc_count; ++i) {
        c += "[[plc]]\nname = \"" + plc_name(i) + "\"\nhost = \"127.0.0.1\"\nport = " +
             std::to_string(relay.port(static_cast<std::size_t>(i))) + "\ntimeout_ms = 500\n";
        c += "[[plc.group]]\nname = \"g\"\ninterval_ms = 100\npublish = \"always\"\n";
        c += "tags = [ { name = \"v\", address = \"D" + std::to_string(100 + i) +
             "\", type = \"int16\", writable = true } ]\n";
    }
    return c;
}

// The time of the last data message of each PLC ("{prefix}/{plc}/g").
std::map<std::string, std::chrono::steady_clock::time_point> last_data(
    const std::vector<tb::Received>& ms) {
    std::map<std::string, std::chrono::steady_clock::time_point> out;
    for (const auto& m : ms)
        for (int i = 0; i < plc_count; ++i)
            if (m.topic == prefix + "/" + plc_name(i) + "/g") out[plc_name(i)] = m.at;
    return out;
}

// (Called inside Recorder::wait with the messages: the recorder is locked there.)
bool all_published_since(const std::vector<tb::Received>& ms,
                         std::chrono::steady_clock::time_point since) {
    const auto last = last_data(ms);
    for (int i = 0; i < plc_count; ++i) {
        const auto it = last.find(plc_name(i));
        if (it == last.end() || it->second < since) return false;
    }
    return true;
}

// Waits until every instance's retained status says "online" (the membership the test means
// to observe is complete), then until every PLC has published since: the joins are over.
bool wait_stable(tb::Recorder& rec, const std::vector<std::string>& names) {
    auto all_online = [&](const std::vector<tb::Received>& ms) {
        std::map<std::string, bool> online;
        for (const auto& m : ms)
            for (const auto& n : names)
                if (m.topic == prefix + "/$bridge/" + n + "/status")
                    online[n] = m.payload.find("\"online\"") != std::string::npos;
        for (const auto& n : names)
            if (!online[n]) return false;
        return true;
    };
    if (!rec.wait(all_online, 30s)) return false;
    const auto joined = std::chrono::steady_clock::now() + 200ms;
    return rec.wait([&](const auto& ms) { return all_published_since(ms, joined); }, 30s);
}

// Polls a stable second and returns, per PLC, how many senders polled it.
std::vector<std::size_t> pollers_per_plc(tb::CountingRelay& relay) {
    relay.reset();
    std::this_thread::sleep_for(1500ms);  // a window of ~15 cycles, not a timing assertion
    std::vector<std::size_t> out;
    for (int i = 0; i < plc_count; ++i)
        out.push_back(relay.senders(static_cast<std::size_t>(i)).size());
    return out;
}

// Publishes a write and returns the responses with its id seen within `wait`.
std::size_t responses_to(tb::Recorder& rec, const std::string& plc, const std::string& id,
                         int value) {
    const nlohmann::json cmd{{"id", id}, {"tag", "v"}, {"value", value}};
    rec.publish(prefix + "/" + plc + "/write", cmd.dump());
    auto count = [&](const std::vector<tb::Received>& ms) {
        std::size_t n = 0;
        for (const auto& m : ms) {
            if (m.topic != prefix + "/" + plc + "/write/response") continue;
            const auto j = nlohmann::json::parse(m.payload, nullptr, false);
            if (j.is_object() && j.value("id", "") == id) ++n;
        }
        return n;
    };
    rec.wait([&](const auto& ms) { return count(ms) > 0; }, 10s);
    std::this_thread::sleep_for(1s);  // a second answer would come from another instance now
    return count(rec.messages());
}

void run_cluster(int instances) {
    if (tb::mosquitto_path().empty()) GTEST_SKIP() << "mosquitto is not installed";
    fins::test::ScratchDir dir("cluster");
    tb::Mosquitto broker(dir.path());
    ASSERT_TRUE(broker.started());
    fins::test::Finsd finsd({});
    ASSERT_TRUE(finsd.started());
    tb::CountingRelay relay(plc_count, finsd.port());
    const auto conf = dir.write("bridge.toml", config_text(relay, broker.port()));
    tb::Recorder rec(broker.port(), {prefix + "/#"});

    std::vector<std::string> names;
    std::vector<std::unique_ptr<tb::Child>> bridges;
    for (int i = 0; i < instances; ++i) {
        names.push_back("edge-" + std::to_string(i + 1));
        bridges.push_back(std::make_unique<tb::Child>(
            std::vector<std::string>{tb::bridge_path, "--config", conf, "--instance", names.back()},
            dir.path() / (names.back() + ".log")));
    }
    ASSERT_TRUE(wait_stable(rec, names)) << bridges[0]->log();

    // Stable membership: each PLC polled by exactly one instance.
    auto pollers = pollers_per_plc(relay);
    for (int i = 0; i < plc_count; ++i)
        EXPECT_EQ(pollers[static_cast<std::size_t>(i)], 1U) << plc_name(i);

    // A write is executed once, by the owner, though every instance receives it.
    const auto writes_before = relay.writes(0);
    EXPECT_EQ(responses_to(rec, plc_name(0), "w-before", 11), 1U);
    EXPECT_EQ(relay.writes(0) - writes_before, 1U);
    auto client = finsd.client();
    EXPECT_EQ(fins::test::words_of(*client, "D100", 1), std::vector<std::uint16_t>{11});

    // kill -9 the owner of press0 (no goodbye: the broker publishes its Will).
    const auto victim = fins::bridge::cluster::rendezvous_owner(names, plc_name(0));
    ASSERT_LT(victim, names.size());
    bridges[victim]->kill(SIGKILL);
    const auto killed = std::chrono::steady_clock::now();
    // Every PLC keeps publishing: the dead instance's share within failover_s (10 s) plus
    // the broker's keep-alive check; the bound here is a generous timeout, the measured
    // failover time is in docs/benchmarks.md.
    ASSERT_TRUE(
        rec.wait([&](const auto& ms) { return all_published_since(ms, killed + 1s); }, 40s));
    pollers = pollers_per_plc(relay);
    for (int i = 0; i < plc_count; ++i)
        EXPECT_EQ(pollers[static_cast<std::size_t>(i)], 1U) << plc_name(i);

    // The new owner executes writes, once.
    const auto writes_after = relay.writes(0);
    EXPECT_EQ(responses_to(rec, plc_name(0), "w-after", 22), 1U);
    EXPECT_EQ(relay.writes(0) - writes_after, 1U);
    EXPECT_EQ(fins::test::words_of(*client, "D100", 1), std::vector<std::uint16_t>{22});

    // The dead instance's status is "offline" (its Will), the survivors' "online".
    for (std::size_t i = 0; i < names.size(); ++i) {
        std::string last;
        for (const auto& m : rec.messages())
            if (m.topic == prefix + "/$bridge/" + names[i] + "/status") last = m.payload;
        const auto j = nlohmann::json::parse(last, nullptr, false);
        ASSERT_TRUE(j.is_object()) << names[i] << ": " << last;
        EXPECT_EQ(j.value("state", ""), i == victim ? "offline" : "online") << names[i];
    }
}

}  // namespace

TEST(ClusterFailover, TwoInstancesShareThePlcsAndTheSurvivorTakesOverAfterKill9) {
    run_cluster(2);
}

TEST(ClusterFailover, ThreeInstancesShareThePlcsAndTheSurvivorsTakeOverAfterKill9) {
    run_cluster(3);
}

// A silent death: SIGSTOP keeps the socket open and quiet (a hung machine, a lost network),
// so only the keep-alive reveals it. The other instance takes its PLCs over; when the frozen
// one continues, its connection is gone, it reconnects, rejoins, and each PLC is again polled
// by exactly one instance.
TEST(ClusterFailover, AFrozenInstanceIsReplacedAndRejoinsWhenItContinues) {
    if (tb::mosquitto_path().empty()) GTEST_SKIP() << "mosquitto is not installed";
    fins::test::ScratchDir dir("cluster-freeze");
    tb::Mosquitto broker(dir.path());
    ASSERT_TRUE(broker.started());
    fins::test::Finsd finsd({});
    ASSERT_TRUE(finsd.started());
    tb::CountingRelay relay(plc_count, finsd.port());
    const auto conf = dir.write("bridge.toml", config_text(relay, broker.port()));
    tb::Recorder rec(broker.port(), {prefix + "/#"});
    const std::vector<std::string> names{"edge-1", "edge-2"};
    tb::Child a({tb::bridge_path, "--config", conf, "--instance", names[0]},
                dir.path() / "edge-1.log");
    tb::Child b({tb::bridge_path, "--config", conf, "--instance", names[1]},
                dir.path() / "edge-2.log");
    ASSERT_TRUE(wait_stable(rec, names)) << a.log();

    ::kill(a.pid(), SIGSTOP);
    const auto frozen = std::chrono::steady_clock::now();
    // The broker publishes edge-1's Will after 1.5 x keep-alive (6 s here): a generous bound.
    ASSERT_TRUE(rec.wait([&](const auto& ms) { return all_published_since(ms, frozen + 1s); }, 60s))
        << b.log();
    auto pollers = pollers_per_plc(relay);
    for (int i = 0; i < plc_count; ++i)
        EXPECT_EQ(pollers[static_cast<std::size_t>(i)], 1U) << plc_name(i);

    std::vector<std::map<std::uint16_t, std::uint64_t>> while_frozen;
    for (int i = 0; i < plc_count; ++i)
        while_frozen.push_back(relay.senders(static_cast<std::size_t>(i)));

    ::kill(a.pid(), SIGCONT);
    // edge-1 finds its connection closed, reconnects and says "online" again.
    auto online_again = [&](const std::vector<tb::Received>& ms) {
        for (const auto& m : ms)
            if (m.topic == prefix + "/$bridge/edge-1/status" && m.at > frozen &&
                m.payload.find("\"online\"") != std::string::npos)
                return true;
        return false;
    };
    ASSERT_TRUE(rec.wait(online_again, 60s)) << a.log();
    std::this_thread::sleep_for(1s);  // both have seen the join
    pollers = pollers_per_plc(relay);
    for (int i = 0; i < plc_count; ++i)
        EXPECT_EQ(pollers[static_cast<std::size_t>(i)], 1U) << plc_name(i);
    // edge-1 polls its share again (another sender than edge-2 while it was frozen), and
    // edge-2 keeps the rest.
    int returned = 0;
    for (int i = 0; i < plc_count; ++i) {
        if (fins::bridge::cluster::rendezvous_owner(names, plc_name(i)) != 0) continue;
        ++returned;
        for (const auto& [port, n] : relay.senders(static_cast<std::size_t>(i)))
            EXPECT_EQ(while_frozen[static_cast<std::size_t>(i)].count(port), 0U) << plc_name(i);
    }
    EXPECT_GT(returned, 0);
}
