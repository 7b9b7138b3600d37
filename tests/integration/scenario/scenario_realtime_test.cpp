// Scenarios that move on their own (issue 26 point 9): finsd started as docs/scenarios.md
// shows it with the shipped real-time example, or any example with --scenario-time real,
// moves memory without `finsd ctl scenario advance`; --scenario-time holds across reload;
// and finsd logs at start the scenario (file, tags, time mode, tick) and the serial ports
// it listens on.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"
#include "integration/support/pty_pair.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

const std::string& examples = scenario_examples;

// Reads `address` until it differs from its first value: true when it did within 10 s
// (bounded in time and in reads; no sleep, each read is a FINS round trip).
bool changes(Client& c, const std::string& address) {
    const auto first = c.read_words(addr(address), 1);
    if (!first) return false;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    for (int i = 0; i < 1000000 && std::chrono::steady_clock::now() < deadline; ++i) {
        const auto now = c.read_words(addr(address), 1);
        if (now && (*now)[0] != (*first)[0]) return true;
    }
    return false;
}

// The docs' command: `finsd --scenario examples/scenarios/live.toml`, then reads.
TEST(ScenarioRealTime, TheShippedLiveExampleMovesWithoutAdvance) {
    Finsd d({"--scenario", examples + "live.toml"});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    EXPECT_TRUE(changes(*c, "D1")) << "the sine";
    EXPECT_TRUE(changes(*c, "D0")) << "seconds since start";
}

// Any example in real time: machine.toml says time = "virtual".
TEST(ScenarioRealTime, ScenarioTimeRealMovesAVirtualExample) {
    ScratchDir dir("scenario-time");
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd d(
        {"--scenario", examples + "machine.toml", "--scenario-time", "real", "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    EXPECT_TRUE(changes(*c, "D100")) << "the spindle's sine";
    // A reload reads the file (virtual) again: the option still holds.
    ASSERT_EQ(ctl(socket, {"scenario", "reload"}).exit_code, 0);
    const auto st = ctl(socket, {"scenario", "status"});
    ASSERT_EQ(st.exit_code, 0) << st.err;
    EXPECT_EQ(Json::parse(st.out, nullptr, false)["scenario"]["time"], "real") << st.out;
    EXPECT_TRUE(changes(*c, "D100")) << "after reload";
}

TEST(ScenarioRealTime, ScenarioTimeVirtualStopsTheLiveExample) {
    ScratchDir dir("scenario-time");
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd d(
        {"--scenario", examples + "live.toml", "--scenario-time", "virtual", "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    const auto st = ctl(socket, {"scenario", "status"});
    EXPECT_EQ(Json::parse(st.out, nullptr, false)["scenario"]["time"], "virtual") << st.out;
    ASSERT_EQ(ctl(socket, {"scenario", "advance", "3"}).exit_code, 0);
    EXPECT_EQ(words_of(*c, "D0", 1), std::vector<std::uint16_t>{3});  // 3 s, exactly
}

TEST(ScenarioRealTime, ScenarioTimeWithoutAScenarioIsRefused) {
    const auto r = run({finsd_path, "--port", "0", "--scenario-time", "real"});
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.err.find("--scenario-time real: there is no scenario to run"), std::string::npos)
        << r.err;
    const auto bad =
        run({finsd_path, "--scenario", examples + "live.toml", "--scenario-time", "fast"});
    EXPECT_EQ(bad.exit_code, 2) << bad.err;
}

// At info, finsd says what it runs: the scenario and the serial ports it listens on.
TEST(ScenarioRealTime, StartLogNamesTheScenarioAndTheSerialPorts) {
    ScratchDir dir("scenario-log");
    PtyPair gateway_line;
    PtyPair host_link_line;
    Finsd d({"--control", (dir.path() / "a.sock").string(), "--scenario", examples + "live.toml",
             "--serial", "scu1.2=" + gateway_line.a() + ",mode=gateway", "--serial",
             "cpu=" + host_link_line.a()},
            {.log_level = "info"});
    ASSERT_TRUE(d.started()) << d.result().err;
    // In the order finsd starts them (each wait reads on from the line before).
    EXPECT_TRUE(d.child().wait_for_stderr("finsd: serial gateway port scu1.2 on " +
                                          gateway_line.a() + ", unit address 85"));
    EXPECT_TRUE(d.child().wait_for_stderr(
        "finsd: scenario " + examples + "live.toml: 6 tags, 0 events, real time x1, tick 100 ms"));
    EXPECT_TRUE(d.child().wait_for_stderr("finsd: serial cpu on " + host_link_line.a()));

    Finsd v({"--control", (dir.path() / "b.sock").string(), "--scenario", examples + "tank.toml"},
            {.log_level = "info"});
    ASSERT_TRUE(v.started()) << v.result().err;
    EXPECT_TRUE(v.child().wait_for_stderr(
        "finsd: scenario " + examples +
        "tank.toml: 6 tags, 1 event, virtual time: moves by `finsd ctl scenario advance`, "
        "tick 100 ms"));
}

}  // namespace
}  // namespace fins::test
