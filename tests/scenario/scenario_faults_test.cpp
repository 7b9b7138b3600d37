// Unit faults of one kind that overlap (issue 26 point 2): each kind is the combination of
// every event holding it (and, for the battery, the operator's own setting), so the end
// of one event never clears what another still holds. One test per kind, each asserting
// the state inside the long event, inside the short one, after the short one ended and
// after both.
#include <gtest/gtest.h>

#include <string>

#include "plc/plc.hpp"
#include "scenario/scenario.hpp"
#include "scenario_support.hpp"

namespace fins::scenario {
namespace {

using test::now;
using test::tag;

EventDef event(FaultKind fault, double at_s, double duration_s, double value = 0) {
    EventDef e;
    e.fault = fault;
    e.at_s = at_s;
    e.duration_s = duration_s;
    e.value = value;
    return e;
}

// A scenario of `events` on `plc` (one constant tag: events need no tag of their own).
std::unique_ptr<Scenario> with_events(plc::Plc& plc, std::vector<EventDef> events) {
    ScenarioDef def;
    def.tags.push_back(tag("D0", SignalKind::constant));
    def.events = std::move(events);
    return test::compile(std::move(def), plc);
}

// Ticks until scenario time `t` (tick 0.1 s): memory and the faults are those of time t,
// an event in force for at_s <= t < at_s + duration_s (run_to(29.9) shows an event ending
// at 30 still holding, run_to(30) ended).
void run_to(Scenario& s, double t) {
    s.start(now);
    for (int bound = 0; bound < 100000 && s.time() < t - 0.05; ++bound)
        s.tick(now);
}

MemoryAddress address(std::uint8_t code, std::uint16_t word, std::uint8_t bit = 0) {
    return {code, word, bit};
}

TEST(ScenarioFaults, AnOfflineEventInsideAnotherDoesNotBringTheUnitBack) {
    plc::Plc plc;
    auto s =
        with_events(plc, {event(FaultKind::offline, 10, 20), event(FaultKind::offline, 12, 2)});
    ASSERT_TRUE(s);
    run_to(*s, 9.9);
    EXPECT_FALSE(s->transport().offline);
    run_to(*s, 11);
    EXPECT_TRUE(s->transport().offline);
    run_to(*s, 13);
    EXPECT_TRUE(s->transport().offline);
    run_to(*s, 15);  // the short one ended at 14, the long one still holds
    EXPECT_TRUE(s->transport().offline);
    run_to(*s, 29.9);
    EXPECT_TRUE(s->transport().offline);
    run_to(*s, 30);
    EXPECT_FALSE(s->transport().offline);
}

TEST(ScenarioFaults, AnOfflineEventOfDurationZeroStaysPastATimedOne) {
    plc::Plc plc;
    auto s = with_events(plc, {event(FaultKind::offline, 10, 0), event(FaultKind::offline, 12, 2)});
    ASSERT_TRUE(s);
    run_to(*s, 15);
    EXPECT_TRUE(s->transport().offline);
    run_to(*s, 100);
    EXPECT_TRUE(s->transport().offline);
}

TEST(ScenarioFaults, LatencyIsTheLargestOfTheActiveEvents) {
    plc::Plc plc;
    auto s = with_events(
        plc, {event(FaultKind::latency, 10, 20, 100), event(FaultKind::latency, 12, 2, 500),
              event(FaultKind::latency, 20, 2, 50)});
    ASSERT_TRUE(s);
    run_to(*s, 11);
    EXPECT_EQ(s->transport().latency_ms, 100u);
    run_to(*s, 13);
    EXPECT_EQ(s->transport().latency_ms, 500u);
    run_to(*s, 15);
    EXPECT_EQ(s->transport().latency_ms, 100u);
    run_to(*s, 21);  // a smaller one inside does not lower it
    EXPECT_EQ(s->transport().latency_ms, 100u);
    run_to(*s, 23);
    EXPECT_EQ(s->transport().latency_ms, 100u);
    run_to(*s, 30);
    EXPECT_EQ(s->transport().latency_ms, 0u);
}

TEST(ScenarioFaults, DropIsTheLargestFractionOfTheActiveEvents) {
    plc::Plc plc;
    // Not nested: the first ends while the second holds.
    auto s = with_events(
        plc, {event(FaultKind::drop, 10, 10, 0.5), event(FaultKind::drop, 15, 10, 0.25)});
    ASSERT_TRUE(s);
    run_to(*s, 11);
    EXPECT_DOUBLE_EQ(s->transport().drop_fraction, 0.5);
    run_to(*s, 16);
    EXPECT_DOUBLE_EQ(s->transport().drop_fraction, 0.5);
    run_to(*s, 21);
    EXPECT_DOUBLE_EQ(s->transport().drop_fraction, 0.25);
    run_to(*s, 25);
    EXPECT_DOUBLE_EQ(s->transport().drop_fraction, 0.0);
}

TEST(ScenarioFaults, EndCodesOfSeveralAreasHoldAtOnce) {
    plc::Plc plc;
    EventDef d = event(FaultKind::end_code, 10, 20);
    d.address.text = "D100";
    d.end_code = 0x1101;
    EventDef w = event(FaultKind::end_code, 12, 2);
    w.address.text = "W0";
    w.end_code = 0x2101;
    EventDef d2 = event(FaultKind::end_code, 20, 2);  // the same area: the newest wins
    d2.address.text = "D5";
    d2.end_code = 0x0401;
    auto s = with_events(plc, {d, w, d2});
    ASSERT_TRUE(s);
    const auto& f = s->transport();
    const auto dm_word = address(0x82, 7);
    const auto w_word = address(0xB1, 3);
    const auto w_bit = address(0x31, 3, 4);
    run_to(*s, 11);
    EXPECT_EQ(f.end_code_for(dm_word), 0x1101);
    EXPECT_EQ(f.end_code_for(w_word), 0);
    run_to(*s, 13);
    EXPECT_EQ(f.end_code_for(dm_word), 0x1101);
    EXPECT_EQ(f.end_code_for(w_word), 0x2101);
    EXPECT_EQ(f.end_code_for(w_bit), 0x2101);        // a bit code names the same area
    EXPECT_EQ(f.end_code_for(address(0xB0, 3)), 0);  // CIO is not W
    run_to(*s, 15);                                  // W ended; D still faulted
    EXPECT_EQ(f.end_code_for(dm_word), 0x1101);
    EXPECT_EQ(f.end_code_for(w_word), 0);
    run_to(*s, 21);
    EXPECT_EQ(f.end_code_for(dm_word), 0x0401);
    run_to(*s, 23);  // the newer one on D ended: the older one's code again
    EXPECT_EQ(f.end_code_for(dm_word), 0x1101);
    run_to(*s, 30);
    EXPECT_EQ(f.end_code_for(dm_word), 0);
    EXPECT_TRUE(f.areas.empty());
}

TEST(ScenarioFaults, ABatteryEventEndingKeepsAnotherOneAndTheOperatorsBatteryLow) {
    plc::Plc plc;
    auto s = with_events(plc, {event(FaultKind::battery, 10, 20), event(FaultKind::battery, 12, 2),
                               event(FaultKind::battery, 40, 5), event(FaultKind::battery, 60, 5)});
    ASSERT_TRUE(s);
    auto& errors = plc.errors();
    run_to(*s, 13);
    EXPECT_TRUE(errors.battery_low());
    run_to(*s, 15);
    EXPECT_TRUE(errors.battery_low());
    EXPECT_TRUE(errors.is_active(plc::battery_error_code));
    run_to(*s, 30);
    EXPECT_FALSE(errors.battery_low());
    EXPECT_FALSE(errors.is_active(plc::battery_error_code));
    // The operator says low (finsd ctl battery-error on); an event ending keeps it low.
    run_to(*s, 35);
    errors.set_battery_low(true, now);
    run_to(*s, 45);
    EXPECT_TRUE(errors.battery_low());
    EXPECT_TRUE(errors.is_active(plc::battery_error_code));
    errors.set_battery_low(false, now);
    EXPECT_FALSE(errors.battery_low());
    // The operator's "off" inside an event does not replace the event's battery.
    run_to(*s, 61);
    errors.set_battery_low(false, now);
    EXPECT_TRUE(errors.battery_low());
    errors.clear_all(now);  // ERROR CLEAR: it recurs while the event holds
    EXPECT_TRUE(errors.is_active(plc::battery_error_code));
    run_to(*s, 65);
    EXPECT_FALSE(errors.battery_low());
    EXPECT_FALSE(errors.is_active(plc::battery_error_code));
}

TEST(ScenarioFaults, FalEventsOfOneNumberAndTheOperatorsFal) {
    plc::Plc plc;
    EventDef long_fal = event(FaultKind::fal, 10, 20);
    long_fal.number = 5;
    EventDef short_fal = event(FaultKind::fal, 12, 2);
    short_fal.number = 5;
    EventDef other = event(FaultKind::fal, 12, 2);
    other.number = 6;
    EventDef over_operator = event(FaultKind::fal, 40, 2);
    over_operator.number = 7;
    EventDef fals_a = event(FaultKind::fals, 50, 5);
    fals_a.number = 9;
    EventDef fals_b = event(FaultKind::fals, 52, 10);
    fals_b.number = 9;
    auto s = with_events(plc, {long_fal, short_fal, other, over_operator, fals_a, fals_b});
    ASSERT_TRUE(s);
    auto& errors = plc.errors();
    run_to(*s, 13);
    EXPECT_TRUE(errors.is_active(0x4105));
    EXPECT_TRUE(errors.is_active(0x4106));
    run_to(*s, 15);
    EXPECT_TRUE(errors.is_active(0x4105));   // the long one holds FAL 5
    EXPECT_FALSE(errors.is_active(0x4106));  // FAL 6 had one event only
    run_to(*s, 30);
    EXPECT_FALSE(errors.is_active(0x4105));
    // FAL 7 raised by the operator (or the ladder) before its event: it stays after.
    ASSERT_TRUE(errors.raise_fal(7, "operator", now));
    run_to(*s, 41);
    EXPECT_TRUE(errors.is_active(0x4107));
    run_to(*s, 43);
    EXPECT_TRUE(errors.is_active(0x4107));
    // FALS 9: two events not nested; the first ending keeps it.
    run_to(*s, 56);
    EXPECT_TRUE(errors.is_active(0xC109));
    run_to(*s, 62);
    EXPECT_FALSE(errors.is_active(0xC109));
}

TEST(ScenarioFaults, OverlappingModeEventsEndInTheModeFromBeforeTheFirst) {
    plc::Plc plc;
    ASSERT_EQ(plc.mode(), plc::OperatingMode::run);
    EventDef program = event(FaultKind::mode, 10, 10);
    program.mode = Mode::program;
    EventDef monitor = event(FaultKind::mode, 15, 15);
    monitor.mode = Mode::monitor;
    auto s = with_events(plc, {program, monitor});
    ASSERT_TRUE(s);
    run_to(*s, 11);
    EXPECT_EQ(plc.mode(), plc::OperatingMode::program);
    run_to(*s, 16);
    EXPECT_EQ(plc.mode(), plc::OperatingMode::monitor);
    run_to(*s, 21);  // program's end does not bring run back while monitor holds
    EXPECT_EQ(plc.mode(), plc::OperatingMode::monitor);
    run_to(*s, 30);  // the last one ends: the mode from before the first
    EXPECT_EQ(plc.mode(), plc::OperatingMode::run);
}

TEST(ScenarioFaults, ANestedModeEventGivesTheModeBackToTheOuterOne) {
    plc::Plc plc;
    EventDef program = event(FaultKind::mode, 10, 20);
    program.mode = Mode::program;
    EventDef monitor = event(FaultKind::mode, 12, 2);
    monitor.mode = Mode::monitor;
    auto s = with_events(plc, {program, monitor});
    ASSERT_TRUE(s);
    run_to(*s, 13);
    EXPECT_EQ(plc.mode(), plc::OperatingMode::monitor);
    run_to(*s, 15);
    EXPECT_EQ(plc.mode(), plc::OperatingMode::program);
    run_to(*s, 30);
    EXPECT_EQ(plc.mode(), plc::OperatingMode::run);
}

TEST(ScenarioFaults, TriggeringAnActiveEventAgainKeepsTheOthers) {
    plc::Plc plc;
    EventDef a = event(FaultKind::offline, 10, 20);
    EventDef b = event(FaultKind::offline, 12, 2);
    b.name = "blip";
    auto s = with_events(plc, {a, b});
    ASSERT_TRUE(s);
    run_to(*s, 13);
    ASSERT_TRUE(s->trigger("blip", now));  // ends and restarts blip: a still holds
    EXPECT_TRUE(s->transport().offline);
    run_to(*s, 16);
    EXPECT_TRUE(s->transport().offline);
    run_to(*s, 30);
    EXPECT_FALSE(s->transport().offline);
}

}  // namespace
}  // namespace fins::scenario
