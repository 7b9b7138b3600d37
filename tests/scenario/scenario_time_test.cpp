// Scenario time is exact (issue 26 points 1 and 6): memory holds the tags at the time
// the scenario says, f(t) by docs/scenarios.md's formulas, from t = 0 on; events are in
// force for at_s <= t < at_s + duration_s; a tag with `when` has its own clock; a
// scenario replacing another (a reload) goes on at its time.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "fins/values.hpp"
#include "plc/plc.hpp"
#include "scenario/scenario.hpp"
#include "scenario_support.hpp"

namespace fins::scenario {
namespace {

using test::compile;
using test::now;
using test::tag;

std::int16_t dm(plc::Plc& plc, std::uint32_t word) {
    return static_cast<std::int16_t>(plc.memory().words(Region::dm)[word]);
}

TagDef ramp(const char* address, double max, double period_s) {
    TagDef t = tag(address, SignalKind::ramp);
    t.min = 0;
    t.max = max;
    t.period_s = period_s;
    return t;
}

// The cases: before this change each read the tick before.
TEST(ScenarioTime, MemoryHoldsTheTagsAtTheTimeTheScenarioSays) {
    plc::Plc plc;
    ScenarioDef def;
    def.tags.push_back(ramp("D0", 1000, 10));
    TagDef sine = tag("D1", SignalKind::sine);
    sine.min = 0;
    sine.max = 1000;
    sine.period_s = 10;
    def.tags.push_back(sine);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    EXPECT_FALSE(s->started());
    s->start(now);
    EXPECT_TRUE(s->started());
    EXPECT_EQ(s->ticks(), 0u);
    EXPECT_EQ(dm(plc, 0), 0);
    EXPECT_EQ(dm(plc, 1), 500);  // the sine's offset at t = 0, before any advance
    s->start(now);               // once only
    EXPECT_EQ(s->ticks(), 0u);
    EXPECT_EQ(s->advance(2.5, now), 25u);
    EXPECT_EQ(dm(plc, 0), 250);
    EXPECT_EQ(dm(plc, 1), 1000);  // the crest at 2.5 s
    s->advance(6.0, now);
    EXPECT_DOUBLE_EQ(s->status().time_s, 8.5);
    EXPECT_EQ(dm(plc, 0), 850);  // the time status says
    s->advance(1.5, now);
    EXPECT_EQ(dm(plc, 0), 1000);  // advance 10: the ramp's end
}

// advance() on a scenario never started computes t = 0 first: the same as start().
TEST(ScenarioTime, AdvanceStartsTheScenarioFirst) {
    plc::Plc plc;
    ScenarioDef def;
    def.tags.push_back(ramp("D0", 1000, 10));
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    EXPECT_EQ(s->advance(0.05, now), 0u);  // less than a tick: none, but started
    EXPECT_TRUE(s->started());
    EXPECT_EQ(s->advance(0.05, now), 1u);  // what the first left makes a tick
    EXPECT_EQ(dm(plc, 0), 10);
}

// Every kind at t = 0 shows its value at 0: stateful kinds their initial state (nothing
// integrated, no step drawn), waves their formula at 0.
TEST(ScenarioTime, EveryKindAtTimeZero) {
    plc::Plc plc;
    plc.memory().words(Region::dm)[90] = 50;  // an input
    plc.memory().words(Region::cio)[0] = 1;   // a counter's input, on
    ScenarioDef def;
    auto wave = [&](const char* address, SignalKind kind) {
        TagDef t = tag(address, kind);
        t.min = 10;
        t.max = 30;
        t.period_s = 4;
        def.tags.push_back(t);
    };
    wave("D0", SignalKind::square);    // max first
    wave("D1", SignalKind::triangle);  // min
    wave("D2", SignalKind::sawtooth);  // min
    wave("D3", SignalKind::ramp);      // min
    TagDef steps = tag("D4", SignalKind::steps);
    steps.steps = {{0, 5}, {1, 7}};
    def.tags.push_back(steps);
    TagDef walk = tag("D5", SignalKind::random_walk);
    walk.min = -100;
    walk.max = 100;
    walk.step = 10;
    walk.initial = 40;
    def.tags.push_back(walk);
    TagDef counter = tag("D6", SignalKind::counter);
    counter.input.text = "CIO0.00";  // on at the start: no rising edge
    counter.initial = 3;
    def.tags.push_back(counter);
    TagDef total = tag("D7", SignalKind::totaliser);
    total.input.text = "D90";
    total.initial = 2;
    def.tags.push_back(total);
    TagDef lag = tag("D8", SignalKind::lag);
    lag.input.text = "D90";
    lag.tau_s = 1;
    lag.initial = 4;
    def.tags.push_back(lag);
    TagDef hysteresis = tag("D9", SignalKind::hysteresis);
    hysteresis.input.text = "D90";
    hysteresis.on_above = 40;
    hysteresis.off_below = 10;
    def.tags.push_back(hysteresis);
    TagDef link = tag("D10", SignalKind::link);
    link.input.text = "D90 + t";
    def.tags.push_back(link);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    s->start(now);
    const std::vector<std::int16_t> at_zero{30, 10, 10, 10, 5, 40, 3, 2, 4, 1, 50};
    for (std::uint32_t i = 0; i < at_zero.size(); ++i)
        EXPECT_EQ(dm(plc, i), at_zero[i]) << "D" << i;
    s->advance(1.0, now);  // t = 1: ten ticks integrated
    EXPECT_EQ(dm(plc, 3), 15);
    EXPECT_EQ(dm(plc, 4), 7);
    EXPECT_EQ(dm(plc, 6), 3);   // still on: no edge
    EXPECT_EQ(dm(plc, 7), 52);  // 2 + 50 x 1 s
    EXPECT_EQ(dm(plc, 8), static_cast<std::int16_t>(std::lround(
                              50 - 46 * std::pow(std::exp(-0.1), 10))));  // 10 lag steps
    EXPECT_EQ(dm(plc, 10), 51);
}

// An event at at_s = 5 for 2 s is in force for 5 <= t < 7: at the tick of 5 and up to the
// tick before 7, so after `advance 5` a stuck sensor is stuck at its value of 5.
TEST(ScenarioTime, AnEventIsInForceFromItsStartUpToItsEnd) {
    plc::Plc plc;
    ScenarioDef def;
    def.tags.push_back(ramp("D0", 1000, 100));  // 10 a second
    EventDef stuck;
    stuck.name = "stuck";
    stuck.at_s = 5;
    stuck.duration_s = 2;
    stuck.fault = FaultKind::stuck;
    stuck.address.text = "D0";
    def.events.push_back(stuck);
    EventDef off;
    off.name = "off";
    off.at_s = 5;
    off.duration_s = 2;
    off.fault = FaultKind::offline;
    def.events.push_back(off);
    EventDef spike;
    spike.name = "spike";
    spike.at_s = 0;  // at the start; duration 0: one tick
    spike.fault = FaultKind::spike;
    spike.value = 1000;
    spike.address.text = "D0";
    def.events.push_back(spike);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    s->start(now);
    EXPECT_EQ(dm(plc, 0), 1000);  // the spike at t = 0
    s->advance(0.1, now);
    EXPECT_EQ(dm(plc, 0), 1);  // its one tick is over
    s->advance(4.8, now);      // t = 4.9: just before
    EXPECT_EQ(dm(plc, 0), 49);
    EXPECT_FALSE(s->transport().offline);
    EXPECT_FALSE(s->status().events[0].active);
    s->advance(0.1, now);  // t = 5: at
    EXPECT_EQ(dm(plc, 0), 50);
    EXPECT_TRUE(s->transport().offline);
    EXPECT_TRUE(s->status().events[0].active);
    s->advance(0.1, now);  // t = 5.1: after
    EXPECT_EQ(dm(plc, 0), 50);
    s->advance(1.8, now);  // t = 6.9: the last tick in force
    EXPECT_EQ(dm(plc, 0), 50);
    EXPECT_TRUE(s->transport().offline);
    s->advance(0.1, now);  // t = 7: ended
    EXPECT_EQ(dm(plc, 0), 70);
    EXPECT_FALSE(s->transport().offline);
    EXPECT_FALSE(s->status().events[0].active);
}

// A trigger starts a unit fault at once (memory holds the present time); a value fault
// first shows at the next tick and lasts its duration from there.
TEST(ScenarioTime, ATriggeredValueFaultStartsAtTheNextTick) {
    plc::Plc plc;
    ScenarioDef def;
    def.tags.push_back(ramp("D0", 1000, 100));
    EventDef spike;
    spike.name = "spike";
    spike.at_s = 1e6;
    spike.fault = FaultKind::spike;  // duration 0: one tick
    spike.value = 1000;
    spike.address.text = "D0";
    def.events.push_back(spike);
    EventDef off;
    off.name = "off";
    off.at_s = 1e6;
    off.duration_s = 1;
    off.fault = FaultKind::offline;
    def.events.push_back(off);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    s->advance(1.0, now);
    ASSERT_TRUE(s->trigger("spike", now));
    ASSERT_TRUE(s->trigger("off", now));
    EXPECT_EQ(dm(plc, 0), 10);  // memory is not recomputed
    EXPECT_TRUE(s->transport().offline);
    s->advance(0.1, now);
    EXPECT_EQ(dm(plc, 0), 1011);  // its one tick
    s->advance(0.1, now);
    EXPECT_EQ(dm(plc, 0), 12);
    s->advance(0.7, now);  // t = 1.9
    EXPECT_TRUE(s->transport().offline);
    s->advance(0.1, now);  // t = 2: a second after the trigger
    EXPECT_FALSE(s->transport().offline);
}

// `when` off: a time-based kind does not advance (its own clock stops); back on, it goes
// on from where it was.
TEST(ScenarioTime, ATagWithWhenHasItsOwnClock) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef r = ramp("D0", 1000, 100);  // 10 a second
    r.when.text = "CIO0.00";
    def.tags.push_back(r);
    TagDef steps = tag("D1", SignalKind::steps);
    steps.steps = {{0, 1}, {2, 2}};
    steps.when.text = "CIO0.00";
    def.tags.push_back(steps);
    TagDef free = ramp("D2", 1000, 100);  // no when: the scenario's time
    def.tags.push_back(free);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    s->advance(50, now);  // off for 50 s: nothing written
    EXPECT_EQ(dm(plc, 0), 0);
    EXPECT_EQ(dm(plc, 1), 0);
    EXPECT_EQ(dm(plc, 2), 500);
    plc.memory().words(Region::cio)[0] = 1;
    s->advance(1, now);  // on for 1 s
    EXPECT_EQ(dm(plc, 0), 10);
    EXPECT_EQ(dm(plc, 1), 1);
    plc.memory().words(Region::cio)[0] = 0;
    s->advance(10, now);  // off: kept, not advanced
    EXPECT_EQ(dm(plc, 0), 10);
    plc.memory().words(Region::cio)[0] = 1;
    s->advance(1.5, now);
    EXPECT_EQ(dm(plc, 0), 25);
    EXPECT_EQ(dm(plc, 1), 2);  // its own 2.5 s
    EXPECT_EQ(dm(plc, 2), 625);
}

// A sliced advance (plan_advance, then tick() in pieces) gives advance()'s memory byte
// for byte; what does not fill a tick is kept for the next call.
TEST(ScenarioTime, TicksRunInSlicesGiveTheMemoryOfOneAdvance) {
    auto def = [] {
        ScenarioDef d;
        d.seed = 9;
        d.tick_s = 0.001;
        TagDef walk = tag("D0", SignalKind::random_walk, ValueType::float64);
        walk.min = -1e6;
        walk.max = 1e6;
        walk.step = 1;
        d.tags.push_back(walk);
        TagDef sine = tag("D4", SignalKind::sine, ValueType::float64);
        sine.max = 10;
        sine.period_s = 0.37;
        d.tags.push_back(sine);
        return d;
    };
    plc::Plc a, b;
    auto sa = compile(def(), a);
    auto sb = compile(def(), b);
    ASSERT_TRUE(sa && sb);
    EXPECT_EQ(sa->advance(12.3456, now), 12345u);
    sb->start(now);
    const auto ticks = sb->plan_advance(12.3456);
    EXPECT_EQ(ticks, 12345u);
    for (std::uint64_t i = 0; i < ticks; ++i)
        sb->tick(now);
    const auto wa = a.memory().words(Region::dm), wb = b.memory().words(Region::dm);
    EXPECT_TRUE(std::equal(wa.begin(), wa.begin() + 8, wb.begin()));
    EXPECT_EQ(sa->plan_advance(0.0004), 1u);  // 0.0006 left over + 0.0004: one tick
    // A week at 1 ms counts every tick.
    EXPECT_EQ(sb->plan_advance(7 * 24 * 3600.0), 604'800'000u);
}

// A reload: the new scenario goes on at the old one's time, stateful tags from what
// memory holds, `when` clocks for the same addresses; past one-shot events are not
// replayed, every_s events go on at their next time.
TEST(ScenarioTime, AScenarioReplacingAnotherGoesOnAtItsTime) {
    plc::Plc plc;
    auto def = [](double total_rate) {
        ScenarioDef d;
        d.tags.push_back(ramp("D0", 1000, 100));
        TagDef total = tag("D1", SignalKind::totaliser);
        total.input.text = std::to_string(total_rate);
        d.tags.push_back(total);
        TagDef r = ramp("D2", 1000, 100);
        r.when.text = "CIO0.00";
        d.tags.push_back(r);
        EventDef once;
        once.name = "once";
        once.at_s = 2;
        once.duration_s = 100;
        once.fault = FaultKind::offline;
        d.events.push_back(once);
        EventDef every;
        every.name = "every";
        every.every_s = 3;
        every.duration_s = 1;
        every.fault = FaultKind::set;
        every.value = -1;
        every.address.text = "D0";
        d.events.push_back(every);
        return d;
    };
    auto old = compile(def(2), plc);
    ASSERT_TRUE(old);
    old->advance(1, now);
    plc.memory().words(Region::cio)[0] = 1;
    old->advance(3.5, now);  // t = 4.5: D2's clock at 3.5, offline since 2
    EXPECT_EQ(dm(plc, 1), 9);
    EXPECT_EQ(dm(plc, 2), 35);
    EXPECT_TRUE(old->transport().offline);
    auto fresh = compile(def(10), plc);
    ASSERT_TRUE(fresh);
    fresh->continue_from(*old);
    old.reset();
    fresh->start(now);
    EXPECT_DOUBLE_EQ(fresh->time(), 4.5);
    EXPECT_EQ(fresh->ticks(), 45u);
    EXPECT_EQ(dm(plc, 0), 45);  // f(4.5), not f(0)
    EXPECT_EQ(dm(plc, 1), 9);   // from memory, nothing integrated at the start
    EXPECT_EQ(dm(plc, 2), 35);
    EXPECT_FALSE(fresh->transport().offline);  // at 2: past, not replayed
    fresh->advance(0.5, now);                  // t = 5
    EXPECT_EQ(dm(plc, 1), 14);                 // + 10 x 0.5 s
    EXPECT_EQ(dm(plc, 2), 40);
    fresh->advance(1, now);  // t = 6: every 3 s
    EXPECT_EQ(dm(plc, 0), -1);
    EXPECT_EQ(fresh->status().events[1].next_start_s, 9);
}

// Another tick_ms: the time rounded down to a whole tick of the new one.
TEST(ScenarioTime, AReplacementWithAnotherTickKeepsTheTimeInItsTicks) {
    plc::Plc plc;
    ScenarioDef d;
    d.tags.push_back(ramp("D0", 1000, 100));
    auto old = compile(d, plc);
    ASSERT_TRUE(old);
    old->advance(4.7, now);
    d.tick_s = 0.5;
    auto fresh = compile(d, plc);
    ASSERT_TRUE(fresh);
    fresh->continue_from(*old);
    fresh->start(now);
    EXPECT_DOUBLE_EQ(fresh->time(), 4.5);
    EXPECT_EQ(dm(plc, 0), 45);
}

}  // namespace
}  // namespace fins::scenario
