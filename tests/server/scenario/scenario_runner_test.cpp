// A CPU Unit's running scenario on the io_context (server/scenario/scenario_runner.hpp),
// issue 26 points 1, 4, 5, 6: memory holds f(0) from the start and f(t) at every time,
// across pause/resume and reload; an advance runs in slices (other handlers run between
// them) and gives the memory of one piece; falling behind real time is counted and logged
// once. The time is passed in (run_due): no sleeps.
#include "server/scenario/scenario_runner.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <string>

#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>
#include <boost/asio/post.hpp>
#include <nlohmann/json.hpp>

#include "plc/plc.hpp"
#include "scenario/scenario.hpp"
#include "server/control/control_scenario.hpp"

namespace fins::server {
namespace {

using namespace std::chrono_literals;
using Json = nlohmann::json;

scenario::TagDef ramp(const char* address, double max, double period_s) {
    scenario::TagDef t;
    t.address.text = address;
    t.kind = scenario::SignalKind::ramp;
    t.type = scenario::ValueType::int16;
    t.max = max;
    t.period_s = period_s;
    return t;
}

// A ramp of 10 a second on D0 and a random walk on D10 (float64: every draw shows).
scenario::ScenarioDef ramping(bool virtual_time, double tick_s = 0.1) {
    scenario::ScenarioDef def;
    def.seed = 5;
    def.tick_s = tick_s;
    def.virtual_time = virtual_time;
    def.tags.push_back(ramp("D0", 30000, 3000));
    scenario::TagDef walk;
    walk.address.text = "D10";
    walk.kind = scenario::SignalKind::random_walk;
    walk.type = scenario::ValueType::float64;
    walk.min = -1e9;
    walk.max = 1e9;
    walk.step = 1;
    def.tags.push_back(walk);
    return def;
}

std::unique_ptr<scenario::Scenario> compiled(scenario::ScenarioDef def, plc::Plc& plc) {
    auto s = scenario::Scenario::compile(std::move(def), plc);
    EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
    return s ? std::move(*s) : nullptr;
}

std::int16_t d0(plc::Plc& plc) {
    return static_cast<std::int16_t>(plc.memory().words(Region::dm)[0]);
}

// Runs `io`'s ready handlers until `done()` (bounded: a count of handlers).
template <class F>
bool run_until(asio::io_context& io, F done) {
    for (int i = 0; i < 1'000'000 && !done(); ++i) {
        io.restart();
        if (io.poll_one() == 0) break;
    }
    return done();
}

TEST(ScenarioRunner, MemoryHoldsTheTimeZeroValuesFromTheStartAndTheTimeAfterEachVerb) {
    asio::io_context io;
    plc::Plc plc;
    auto def = ramping(true);
    def.tags[0].min = 500;  // f(0) is not 0; still 10 a second
    def.tags[0].max = 30500;
    ScenarioRunner runner(io, compiled(def, plc), {}, "test");
    runner.start();
    EXPECT_EQ(d0(plc), 500);
    EXPECT_EQ(runner.run_status().status.time_s, 0.0);
    EXPECT_EQ(runner.advance(2.5), 25u);
    EXPECT_EQ(d0(plc), 525);
    runner.pause();
    runner.resume();
    EXPECT_EQ(runner.advance(2.5), 25u);
    EXPECT_EQ(d0(plc), 550);
    EXPECT_DOUBLE_EQ(runner.run_status().status.time_s, 5.0);
}

TEST(ScenarioRunner, RealTimeTicksGiveTheTimeOfTheirTickAcrossPauseAndResume) {
    asio::io_context io;
    plc::Plc plc;
    ScenarioRunner runner(io, compiled(ramping(false), plc), {}, "test");
    runner.start();
    EXPECT_EQ(d0(plc), 0);  // f(0) at the start, before the first period
    runner.run_due(runner.next_due());
    EXPECT_EQ(d0(plc), 1);
    EXPECT_EQ(runner.scenario().ticks(), 1u);
    runner.pause();
    runner.run_due(runner.next_due() + 10s);  // paused: nothing
    EXPECT_EQ(runner.scenario().ticks(), 1u);
    runner.resume();
    runner.run_due(runner.next_due());
    EXPECT_EQ(d0(plc), 2);  // the paused periods are not run
    EXPECT_DOUBLE_EQ(runner.run_status().status.time_s, 0.2);
    EXPECT_EQ(runner.run_status().late_ticks, 0u);
    runner.stop();
}

// time_scale 1000 at a 100 ms tick: a period of 100 us. A second late runs max_catch_up
// ticks and drops the rest: counted, and logged once a minute at most.
TEST(ScenarioRunner, FallingBehindRealTimeIsCountedAndLoggedOnce) {
    auto sink = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(16);
    sink->set_level(spdlog::level::warn);
    auto logger = spdlog::default_logger();
    logger->sinks().push_back(sink);
    asio::io_context io;
    plc::Plc plc;
    auto def = ramping(false);
    def.time_scale = 1000;
    ScenarioRunner runner(io, compiled(def, plc), {}, "fast.toml");
    runner.start();
    const auto t0 = runner.next_due();
    runner.run_due(t0 + 1s);  // 10,001 periods due by then
    auto st = runner.run_status();
    EXPECT_EQ(st.status.ticks, ScenarioRunner::max_catch_up);
    EXPECT_EQ(st.late_ticks, 10'001u - ScenarioRunner::max_catch_up);
    EXPECT_NEAR(st.behind_s, 999.1, 1e-9);
    EXPECT_GT(runner.next_due(), t0 + 1s);  // on the grid, after now
    EXPECT_LE(runner.next_due(), t0 + 1s + 100us);
    runner.run_due(t0 + 2s);  // behind again, within the minute: counted, not logged
    EXPECT_EQ(runner.run_status().late_ticks, 2 * 10'000u - 2 * ScenarioRunner::max_catch_up + 1);
    auto lines = sink->last_formatted();
    EXPECT_EQ(std::count_if(lines.begin(), lines.end(),
                            [](const std::string& l) {
                                return l.find("fast.toml falls behind real time") !=
                                       std::string::npos;
                            }),
              1);
    runner.run_due(t0 + 63s);  // a minute later: said again, with the total
    lines = sink->last_formatted();
    EXPECT_EQ(std::count_if(
                  lines.begin(), lines.end(),
                  [](const std::string& l) { return l.find("falls behind") != std::string::npos; }),
              2);
    // The control status carries it.
    const Json status = handle_scenario_request(&runner, Json{{"action", "status"}});
    EXPECT_EQ(status["scenario"]["late_ticks"], runner.run_status().late_ticks);
    EXPECT_GT(status["scenario"]["behind_s"].get<double>(), 6000.0);
    runner.stop();
    auto& sinks = logger->sinks();
    sinks.erase(std::remove(sinks.begin(), sinks.end(), sink), sinks.end());
}

// An advance runs in slices: other handlers run between them, the other verbs are
// refused meanwhile with a clear error, status tells the progress, and the memory at the
// end is the memory of the same advance in one piece.
TEST(ScenarioRunner, AnAdvanceRunsInSlicesAndGivesTheMemoryOfOnePiece) {
    asio::io_context io;
    plc::Plc sliced, whole;
    const auto def = ramping(true, 0.001);
    ScenarioRunner runner(io, compiled(def, sliced), {}, "test");
    runner.start();
    std::optional<Json> answer;
    handle_scenario_request(&runner, Json{{"action", "advance"}, {"seconds", 600}},
                            [&](Json a) { answer = std::move(a); });
    // 600,000 ticks take more than a slice: the answer waits, the status answers.
    ASSERT_FALSE(answer);
    const Json st = handle_scenario_request(&runner, Json{{"action", "status"}});
    EXPECT_EQ(st["scenario"]["advancing"]["ticks"], 600'000);
    for (const char* verb : {"pause", "resume", "reload", "trigger"}) {
        const Json refused =
            handle_scenario_request(&runner, Json{{"action", verb}, {"event", "x"}});
        EXPECT_NE(refused.value("error", "").find("an advance is running"), std::string::npos)
            << verb << ": " << refused.dump();
    }
    std::optional<Json> second;
    handle_scenario_request(&runner, Json{{"action", "advance"}, {"seconds", 1}},
                            [&](Json a) { second = std::move(a); });
    ASSERT_TRUE(second);
    EXPECT_NE(second->value("error", "").find("an advance is running"), std::string::npos);
    // A handler posted now (a FINS request) runs before the advance ends.
    bool served = false;
    asio::post(io, [&] { served = true; });
    ASSERT_TRUE(run_until(io, [&] { return served; }));
    EXPECT_FALSE(answer);
    EXPECT_GT(runner.run_status().advance_done, 0u);
    ASSERT_TRUE(run_until(io, [&] { return answer.has_value(); }));
    EXPECT_EQ((*answer)["ok"], true);
    EXPECT_EQ((*answer)["ticks"], 600'000);
    EXPECT_DOUBLE_EQ((*answer)["time_s"].get<double>(), 600.0);
    EXPECT_FALSE(runner.run_status().advancing);
    EXPECT_TRUE(runner.busy().empty());

    auto one = compiled(def, whole);
    ASSERT_TRUE(one);
    EXPECT_EQ(one->advance(600, plc::TimePoint{}), 600'000u);
    const auto a = sliced.memory().words(Region::dm), b = whole.memory().words(Region::dm);
    EXPECT_TRUE(std::equal(a.begin(), a.begin() + 16, b.begin()));
    EXPECT_EQ(d0(sliced), 6000);
}

// A runner destroyed while an advance runs answers it (nothing waits forever).
TEST(ScenarioRunner, AnAdvanceCutShortByTheEndIsAnswered) {
    asio::io_context io;
    plc::Plc plc;
    std::optional<Json> answer;
    {
        ScenarioRunner runner(io, compiled(ramping(true, 0.001), plc), {}, "test");
        runner.start();
        handle_scenario_request(&runner, Json{{"action", "advance"}, {"seconds", 600}},
                                [&](Json a) { answer = std::move(a); });
        ASSERT_FALSE(answer);
    }
    ASSERT_TRUE(answer);
    EXPECT_NE(answer->value("error", "").find("stopped"), std::string::npos);
    io.restart();
    io.poll();  // the posted slice finds the runner gone
}

// A reload goes on at the scenario's time: memory holds the new definition at that time.
TEST(ScenarioRunner, AReloadKeepsTheScenarioTime) {
    asio::io_context io;
    plc::Plc plc;
    auto next = ramping(true);
    next.tags[0].min = 1000;  // still 10 a second
    next.tags[0].max = 31000;
    ScenarioRunner runner(
        io, compiled(ramping(true), plc),
        [&]() -> ScenarioRunner::Compiled { return compiled(next, plc); }, "test");
    runner.start();
    runner.advance(4.5);
    EXPECT_EQ(d0(plc), 45);
    ASSERT_TRUE(runner.reload());
    EXPECT_DOUBLE_EQ(runner.run_status().status.time_s, 4.5);
    EXPECT_EQ(d0(plc), 1045);  // the new ramp at 4.5 s, at once
    runner.advance(0.5);
    EXPECT_EQ(d0(plc), 1050);
    EXPECT_EQ(runner.run_status().reloads, 1u);
}

}  // namespace
}  // namespace fins::server
