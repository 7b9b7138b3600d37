// The io_context's one timer for scenario ticks (server/scenario/scenario_ticker.hpp):
// clients due at one instant run in one expiry, in the order they were scheduled, once
// each; a cancel (also from another client's due()) means no call; a client scheduling
// again from due() runs at a later expiry; a plant's runners share it.
#include "server/scenario/scenario_ticker.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <memory>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "plc/plc.hpp"
#include "scenario/scenario.hpp"
#include "server/scenario/scenario_runner.hpp"

namespace fins::server {
namespace {

using namespace std::chrono_literals;
using Clock = ScenarioTicker::Clock;

struct Recorder final : ScenarioTicker::Client {
    int id = 0;
    std::vector<int>* log = nullptr;
    std::function<void()> then;
    void due() noexcept override {
        log->push_back(id);
        if (then) then();
    }
};

TEST(ScenarioTicker, ClientsDueAtOneInstantRunInOneExpiryInTheirOrder) {
    asio::io_context io;
    auto& ticker = asio::use_service<ScenarioTicker>(io);
    std::vector<int> log;
    std::vector<Recorder> clients(100);
    const auto at = Clock::now() + 20ms;
    for (std::size_t i = 0; i < clients.size(); ++i) {
        clients[i].id = static_cast<int>(i);
        clients[i].log = &log;
        ticker.schedule(clients[i], at);
    }
    // Scheduling again replaces the earlier time: 7 is due once, later. (Far enough later
    // that a first expiry delayed by a loaded machine does not find 7 due too: 10 ms was
    // not, under a load average of 8.)
    ticker.schedule(clients[7], at + 1s);
    EXPECT_EQ(ticker.pending(), 100u);
    io.run_for(10s);  // returns when nothing is left to wait for
    ASSERT_EQ(log.size(), 100u);
    std::size_t k = 0;
    for (int i = 0; i < 100; ++i) {
        if (i == 7) continue;
        EXPECT_EQ(log[k++], i);
    }
    EXPECT_EQ(log.back(), 7);
    EXPECT_EQ(ticker.expiries(), 2u);
    EXPECT_EQ(ticker.pending(), 0u);
}

TEST(ScenarioTicker, ACancelledClientIsNotCalledEvenFromInsideTheSameExpiry) {
    asio::io_context io;
    auto& ticker = asio::use_service<ScenarioTicker>(io);
    std::vector<int> log;
    Recorder a, b, c;
    a.id = 1;
    b.id = 2;
    c.id = 3;
    a.log = b.log = c.log = &log;
    a.then = [&] { ticker.cancel(b); };  // b is due in this very expiry
    const auto at = Clock::now() + 10ms;
    ticker.schedule(a, at);
    ticker.schedule(b, at);
    ticker.schedule(c, at);
    ticker.cancel(c);
    ticker.cancel(c);  // twice is harmless
    io.run_for(2s);
    EXPECT_EQ(log, (std::vector<int>{1}));
}

TEST(ScenarioTicker, AClientSchedulingAgainFromDueRunsAtALaterExpiry) {
    asio::io_context io;
    auto& ticker = asio::use_service<ScenarioTicker>(io);
    std::vector<int> log;
    Recorder a;
    a.id = 1;
    a.log = &log;
    int rounds = 0;
    // Even at a time already past: the next expiry runs it, not this one.
    a.then = [&] {
        if (++rounds < 5) ticker.schedule(a, Clock::now() - 1s);
    };
    ticker.schedule(a, Clock::now());
    io.run_for(2s);
    EXPECT_EQ(log.size(), 5u);
    EXPECT_EQ(ticker.expiries(), 5u);
}

// A plant's real-time runners in one phase group tick from one expiry per period.
TEST(ScenarioTicker, APlantsRunnersInOnePhaseGroupShareOneExpiryPerPeriod) {
    asio::io_context io;
    std::vector<std::unique_ptr<plc::Plc>> plcs;
    std::vector<std::unique_ptr<ScenarioRunner>> runners;
    for (int u = 0; u < 20; ++u) {
        plcs.push_back(std::make_unique<plc::Plc>());
        scenario::ScenarioDef def;
        def.tick_s = 0.02;
        def.virtual_time = false;
        scenario::TagDef t;
        t.address.text = "D0";
        t.kind = scenario::SignalKind::counter;
        t.type = scenario::ValueType::uint16;
        t.input.text = "1";
        def.tags.push_back(t);
        auto compiled = scenario::Scenario::compile(std::move(def), *plcs.back());
        ASSERT_TRUE(compiled.has_value()) << compiled.error().message;
        runners.push_back(
            std::make_unique<ScenarioRunner>(io, std::move(*compiled), nullptr, "test"));
    }
    for (auto& r : runners)
        r->start(0.5);  // every runner at the same phase: one group
    auto& ticker = asio::use_service<ScenarioTicker>(io);
    io.run_for(210ms);
    for (auto& r : runners)
        r->stop();
    const auto ticks = runners.front()->scenario().status().ticks;
    EXPECT_GE(ticks, 2u);
    // Every unit ticked alike (a unit started just after the group's instant passed
    // joins it one period later).
    for (auto& r : runners)
        EXPECT_NEAR(static_cast<double>(r->scenario().status().ticks), static_cast<double>(ticks),
                    1.0);
    // About one expiry per period for the 20 units, not 20 (a late period may run in two).
    EXPECT_LE(ticker.expiries(), 2 * ticks + 1);
    EXPECT_EQ(ticker.pending(), 0u);
}

}  // namespace
}  // namespace fins::server
