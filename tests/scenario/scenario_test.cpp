// The scenario model on a virtual CPU Unit, no sockets: signal kinds, links in dependency
// order, events, forcing, the write access log, compile errors, determinism.
#include "scenario/scenario.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

#include "fins/values.hpp"
#include "plc/plc.hpp"
#include "scenario_support.hpp"

namespace fins::scenario {
namespace {

using test::compile;
using test::now;
using test::tag;

TagDef link(std::string address, std::string expr, ValueType type = ValueType::int16) {
    TagDef t = tag(std::move(address), SignalKind::link, type);
    t.input.text = std::move(expr);
    return t;
}

std::string compile_error(ScenarioDef def, const char* profile = "cj2h") {
    plc::Plc plc(*plc::find_profile(profile));
    auto s = Scenario::compile(std::move(def), plc);
    EXPECT_FALSE(s.has_value());
    return s ? "" : s.error().message;
}

std::uint16_t dm(plc::Plc& plc, std::uint32_t word) {
    return plc.memory().words(Region::dm)[word];
}

TEST(Scenario, SineFollowsTheIssueFormulaAndLinksReadItInTheSameTick) {
    plc::Plc plc;
    ScenarioDef def;
    // The link comes first in the file: dependency order still computes D100 first.
    def.tags.push_back(link("D101", "2 * D100"));
    TagDef sine = tag("D100", SignalKind::sine);
    sine.min = 0;
    sine.max = 1000;
    sine.period_s = 10;
    def.tags.push_back(sine);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    s->start(now);  // t = 0
    EXPECT_EQ(dm(plc, 100), 500);
    EXPECT_EQ(dm(plc, 101), 1000);
    EXPECT_EQ(s->advance(2.5, now), 25u);  // ticks at 0.1 ... 2.5
    EXPECT_EQ(dm(plc, 100), 1000);
    EXPECT_EQ(dm(plc, 101), 2000);
    s->advance(5.0, now);  // t = 7.5
    EXPECT_EQ(dm(plc, 100), 0);
    EXPECT_DOUBLE_EQ(s->time(), 7.5);
}

// Values are rounded half away from zero (std::llround) and clamped to the type.
TEST(Scenario, ValuesAreRoundedHalfAwayFromZeroAndClampedToTheType) {
    const std::vector<std::pair<double, std::int32_t>> cases = {
        {2.5, 3},           {-2.5, -3},   {0.49999999999999994, 0}, {-0.49999999999999994, 0},
        {1.4999999, 1},     {-1.5, -2},   {32767.4, 32767},         {32767.6, 32767},
        {-32768.6, -32768}, {1e9, 32767}, {-1e300, -32768},         {0.5, 1}};
    for (const auto& [value, expected] : cases) {
        plc::Plc plc;
        ScenarioDef def;
        TagDef c = tag("D10", SignalKind::constant);
        c.value = value;
        def.tags.push_back(c);
        TagDef u = tag("D11", SignalKind::constant, ValueType::uint16);
        u.value = value;
        def.tags.push_back(u);
        TagDef d = tag("D12", SignalKind::constant, ValueType::int32);
        d.value = value;
        def.tags.push_back(d);
        auto s = compile(def, plc);
        ASSERT_TRUE(s);
        s->tick(now);
        EXPECT_EQ(static_cast<std::int16_t>(dm(plc, 10)), expected) << value;
        EXPECT_EQ(dm(plc, 11),
                  std::clamp<std::int64_t>(std::llround(std::clamp(value, 0.0, 65535.0)), 0, 65535))
            << value;
        const auto w = plc.memory().words(Region::dm);
        // The int32 read back as `fins --as int32` reads it.
        const auto v32 = words_to_int32(Words(w.data() + 12, 2)).value_or(0);
        EXPECT_EQ(v32, std::llround(std::clamp(value, -2147483648.0, 2147483647.0))) << value;
    }
}

// The sine is its own polynomial on the phase as a fraction of the period: the issue's
// formula within 1e-9 over a long run, and quarter periods exact.
TEST(Scenario, SineMatchesTheFormulaOverALongRun) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef sine = tag("D200", SignalKind::sine, ValueType::float64);
    sine.min = -3.5;
    sine.max = 1234.25;
    sine.period_s = 7.3;
    sine.phase_s = 0.45;
    def.tags.push_back(sine);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    const auto w = plc.memory().words(Region::dm);
    s->start(now);
    for (int i = 0; i < 3000; ++i) {
        if (i > 0) s->tick(now);
        const double t = 0.1 * i;
        const double expected =
            (sine.min + sine.max) / 2 +
            (sine.max - sine.min) / 2 *
                std::sin(2 * std::numbers::pi * (t + sine.phase_s) / sine.period_s);
        EXPECT_NEAR(words_to_double(Words(w.data() + 200, 4)).value_or(1e300), expected, 1e-9)
            << "t = " << t;
    }
}

TEST(Scenario, WaveformsAndSteps) {
    plc::Plc plc;
    ScenarioDef def;
    def.tick_s = 0.5;
    for (auto [addr, kind] : {std::pair{"D0", SignalKind::square},
                              {"D1", SignalKind::triangle},
                              {"D2", SignalKind::sawtooth},
                              {"D3", SignalKind::ramp}}) {
        TagDef t = tag(addr, kind);
        t.min = 0;
        t.max = 100;
        t.period_s = 4;
        def.tags.push_back(t);
    }
    TagDef steps = tag("D4", SignalKind::steps);
    steps.steps = {{0, 5}, {1, 7}, {2, 9}};
    steps.repeat_s = 3;
    def.tags.push_back(steps);
    TagDef k = tag("D5", SignalKind::constant, ValueType::float32);
    k.value = 1.5;
    def.tags.push_back(k);
    auto s = compile(def, plc);
    s->start(now);  // t = 0
    EXPECT_EQ(dm(plc, 0), 100);
    EXPECT_EQ(dm(plc, 1), 0);
    EXPECT_EQ(dm(plc, 4), 5);
    EXPECT_EQ(words_to_float(std::span<const std::uint16_t>(&plc.memory().words(Region::dm)[5], 2))
                  .value(),
              1.5f);
    s->advance(1.0, now);  // t = 1
    EXPECT_EQ(dm(plc, 1), 50);
    EXPECT_EQ(dm(plc, 2), 25);
    EXPECT_EQ(dm(plc, 3), 25);
    EXPECT_EQ(dm(plc, 4), 7);
    s->advance(2.0, now);  // t = 3
    EXPECT_EQ(dm(plc, 0), 0);
    EXPECT_EQ(dm(plc, 1), 50);
    EXPECT_EQ(dm(plc, 2), 75);
    EXPECT_EQ(dm(plc, 4), 5);  // the schedule restarted at 3 s
    s->advance(3.0, now);      // t = 6: the ramp holds its max
    EXPECT_EQ(dm(plc, 3), 100);
}

TEST(Scenario, PumpOnMakesTheLevelRiseThroughWhenAndTotaliser) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef flow = link("D10", "if(CIO0.00, 50, 0)");
    def.tags.push_back(flow);
    TagDef level = tag("D11", SignalKind::totaliser, ValueType::float32);
    level.input.text = "D10 - 20 * CIO0.01";  // the valve drains
    def.tags.push_back(level);
    auto s = compile(def, plc);
    auto level_value = [&] {
        return words_to_float(
                   std::span<const std::uint16_t>(&plc.memory().words(Region::dm)[11], 2))
            .value();
    };
    s->advance(1.0, now);
    EXPECT_EQ(level_value(), 0.0f);
    plc.memory().words(Region::cio)[0] = 0x0001;  // the HMI switches the pump on
    s->advance(1.0, now);
    EXPECT_NEAR(level_value(), 50.0f, 1e-3);
    plc.memory().words(Region::cio)[0] = 0x0002;  // pump off, valve open
    s->advance(1.0, now);
    EXPECT_NEAR(level_value(), 30.0f, 1e-3);
}

TEST(Scenario, CounterCountsEdgesAndTakesAClientResetAsItsState) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef pulse = tag("W0.00", SignalKind::square, ValueType::boolean);
    pulse.min = 0;
    pulse.max = 1;
    pulse.period_s = 1;
    def.tags.push_back(pulse);
    TagDef count = tag("D20", SignalKind::counter, ValueType::uint16);
    count.input.text = "W0.00";
    def.tags.push_back(count);
    auto s = compile(def, plc);
    s->advance(10.0, now);
    EXPECT_EQ(dm(plc, 20), 10);
    plc.memory().words(Region::dm)[20] = 0;  // the HMI resets the counter
    s->advance(3.0, now);
    EXPECT_EQ(dm(plc, 20), 3);
}

TEST(Scenario, LagFollowsTheSetpointAClientWrites) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef pv = tag("D30", SignalKind::lag);
    pv.input.text = "D31";
    pv.tau_s = 2;
    def.tags.push_back(pv);
    auto s = compile(def, plc);
    plc.memory().words(Region::dm)[31] = 800;
    s->advance(2.0, now);  // one time constant: 63 %
    EXPECT_NEAR(dm(plc, 30), 800 * (1 - std::exp(-1.0)), 2);
    s->advance(20.0, now);
    EXPECT_EQ(dm(plc, 30), 800);
}

TEST(Scenario, HysteresisAndDelay) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef ramp = tag("D40", SignalKind::ramp);
    ramp.min = 0;
    ramp.max = 100;
    ramp.period_s = 10;
    def.tags.push_back(ramp);
    TagDef alarm = tag("W1.00", SignalKind::hysteresis, ValueType::boolean);
    alarm.input.text = "D40";
    alarm.on_above = 50;
    alarm.off_below = 20;
    def.tags.push_back(alarm);
    TagDef delayed = link("D41", "D40");
    delayed.delay_s = 1;
    def.tags.push_back(delayed);
    auto s = compile(def, plc);
    s->advance(0.5, now);
    EXPECT_EQ(dm(plc, 41), 0);  // nothing written before the delay has passed
    s->advance(5.5, now);       // t = 6.0
    EXPECT_EQ(plc.memory().words(Region::work)[1] & 1, 1);
    EXPECT_EQ(dm(plc, 41), 50);  // D40 of t = 5.0
}

TEST(Scenario, AForcedBitIsNotChangedAndWritesAreLoggedAsTheCpuUnits) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef on = tag("CIO5.03", SignalKind::constant, ValueType::boolean);
    on.value = 1;
    def.tags.push_back(on);
    plc.memory().force_bit(Region::cio, 5, 3, false);
    auto s = compile(def, plc);
    s->advance(1.0, now);
    EXPECT_EQ(plc.memory().words(Region::cio)[5] & 0x0008, 0);
    ASSERT_EQ(plc.write_access_log().size(), 1u);
    EXPECT_EQ(plc.write_access_log().at(0).source.node, 0);
    plc.memory().release_bit(Region::cio, 5, 3);
    s->advance(0.1, now);
    EXPECT_EQ(plc.memory().words(Region::cio)[5] & 0x0008, 0x0008);
}

// Word tags are written straight on the area's words (not through IoMemory::write): a
// forced bit inside a word tag keeps its state, the other bits take the value, and a
// client's write to a stateful tag is still seen.
// The scenario's record (node 0.0.0) is written at the first tick that writes in each
// second of the host clock: a client's write in that second stays after it until the next.
TEST(Scenario, TheWriteAccessRecordIsWrittenOncePerHostSecond) {
    plc::Plc plc;
    ScenarioDef def;
    def.tags.push_back(tag("D10", SignalKind::sine));
    def.tags.back().max = 100;
    auto s = compile(def, plc);
    auto& log = plc.write_access_log();
    s->tick(now);
    ASSERT_EQ(log.size(), 1u);
    const auto first = log.at(0).time;
    log.record(NodeAddress{0, 5, 0}, CommandCode{0x01, 0x02}, EndCode::normal_completion, now);
    s->tick(now + std::chrono::milliseconds(500));  // same second: no record
    ASSERT_EQ(log.size(), 2u);
    EXPECT_EQ(log.at(0).time, first);
    // Fill the log: the least recently written goes first. Node 0's record is older than
    // node 5's, so it goes before node 5's.
    for (std::uint8_t n = 6; n < 24; ++n)
        log.record(NodeAddress{0, n, 0}, CommandCode{0x01, 0x02}, EndCode::normal_completion, now);
    log.record(NodeAddress{0, 30, 0}, CommandCode{0x01, 0x02}, EndCode::normal_completion, now);
    EXPECT_EQ(log.at(0).source.node, 5);
    // The next second: the scenario's record again, with that second's time.
    s->tick(now + std::chrono::milliseconds(1200));
    EXPECT_EQ(log.at(19).source.node, 0);
    EXPECT_NE(log.at(19).time, first);
}

TEST(Scenario, WordTagsKeepForcedBitsAndSeeClientWrites) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef word = tag("CIO7", SignalKind::constant, ValueType::uint16);
    word.value = 0x00FF;
    def.tags.push_back(word);
    TagDef total = tag("W40", SignalKind::totaliser, ValueType::int32);
    total.input.text = "10";
    def.tags.push_back(total);
    plc.memory().force_bit(Region::cio, 7, 9, true);   // forced ON
    plc.memory().force_bit(Region::cio, 7, 0, false);  // forced OFF
    auto s = compile(def, plc);
    s->advance(1.0, now);
    EXPECT_EQ(plc.memory().words(Region::cio)[7], 0x02FE);
    const auto w = plc.memory().words(Region::work);
    EXPECT_EQ(words_to_int32(Words(&w[40], 2)).value_or(-1), 10);  // 10 ticks x 10 x 0.1 s
    // A client writes 1000 to the totaliser: it goes on from there.
    const auto thousand = int32_to_words(1000);
    plc.memory().words(Region::work)[40] = thousand[0];
    plc.memory().words(Region::work)[41] = thousand[1];
    s->advance(0.1, now);
    EXPECT_EQ(words_to_int32(Words(&w[40], 2)).value_or(-1), 1001);
    plc.memory().release_bit(Region::cio, 7, 9);
    plc.memory().release_bit(Region::cio, 7, 0);
    s->advance(0.1, now);
    EXPECT_EQ(plc.memory().words(Region::cio)[7], 0x00FF);
}

TEST(Scenario, ValueFaultsAndUnitFaults) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef ramp = tag("D50", SignalKind::ramp);
    ramp.min = 0;
    ramp.max = 100;
    ramp.period_s = 10;
    def.tags.push_back(ramp);
    EventDef stuck;
    stuck.at_s = 2;
    stuck.duration_s = 3;
    stuck.fault = FaultKind::stuck;
    stuck.address.text = "D50";
    def.events.push_back(stuck);
    EventDef fal;
    fal.name = "overheat";
    fal.at_s = 100;
    fal.duration_s = 1;
    fal.fault = FaultKind::fal;
    fal.number = 7;
    def.events.push_back(fal);
    EventDef off;
    off.every_s = 4;
    off.duration_s = 1;
    off.fault = FaultKind::offline;
    def.events.push_back(off);
    auto s = compile(def, plc);
    s->advance(3.9, now);  // t = 3.9
    EXPECT_EQ(dm(plc, 50), 20);
    EXPECT_FALSE(s->transport().offline);
    s->advance(0.1, now);  // t = 4.0: offline from 4
    EXPECT_TRUE(s->transport().offline);
    s->advance(0.1, now);  // t = 4.1
    EXPECT_TRUE(s->transport().offline);
    s->advance(1.0, now);  // t = 5.1: stuck ended at 5, offline at 5
    EXPECT_EQ(dm(plc, 50), 51);
    EXPECT_FALSE(s->transport().offline);
    ASSERT_TRUE(s->trigger("overheat", now));
    EXPECT_TRUE(plc.errors().is_active(0x4107));
    s->advance(1.1, now);
    EXPECT_FALSE(plc.errors().is_active(0x4107));
    EXPECT_FALSE(s->trigger("nope", now));
}

TEST(Scenario, SameSeedAndSameClientWritesGiveTheSameMemory) {
    auto run = [](std::uint64_t seed) {
        plc::Plc plc;
        ScenarioDef def;
        def.seed = seed;
        TagDef walk = tag("D60", SignalKind::random_walk, ValueType::float64);
        walk.min = -100;
        walk.max = 100;
        walk.step = 3;
        def.tags.push_back(walk);
        def.tags.push_back(link("D64", "D60 + noise(5) + uniform(0, 1) + D70"));
        TagDef pv = tag("D65", SignalKind::lag, ValueType::float32);
        pv.input.text = "D70";
        pv.noise = 0.5;
        def.tags.push_back(pv);
        auto s = Scenario::compile(def, plc);
        for (int i = 0; i < 50; ++i) {
            if (i == 20) plc.memory().words(Region::dm)[70] = 300;  // a client write
            (*s)->advance(0.1, now);
        }
        auto d = plc.memory().words(Region::dm);
        return std::vector<std::uint16_t>(d.begin(), d.begin() + 100);
    };
    EXPECT_EQ(run(42), run(42));
    EXPECT_NE(run(42), run(43));
}

TEST(Scenario, CompileErrorsNameTheProblem) {
    ScenarioDef cycle;
    cycle.tags = {link("D1", "D2 + 1"), link("D2", "D3"), link("D3", "D1")};
    EXPECT_EQ(compile_error(cycle), "the links form a cycle: D1 -> D2 -> D3 -> D1");

    ScenarioDef read_only;
    read_only.tags = {tag("A10", SignalKind::constant)};
    EXPECT_EQ(compile_error(read_only), "A10 is in a read-only area");

    ScenarioDef no_bank;
    no_bank.tags = {tag("E3_0", SignalKind::constant)};
    EXPECT_NE(compile_error(no_bank, "cj1m").find("has no E3_0"), std::string::npos);

    ScenarioDef bit_as_word;
    bit_as_word.tags = {tag("CIO0.01", SignalKind::constant)};
    EXPECT_NE(compile_error(bit_as_word).find("must be \"bool\""), std::string::npos);

    ScenarioDef word_as_bit;
    word_as_bit.tags = {tag("D0", SignalKind::constant, ValueType::boolean)};
    EXPECT_NE(compile_error(word_as_bit).find("needs a bit address"), std::string::npos);

    ScenarioDef overlap;
    overlap.tags = {tag("D0", SignalKind::constant, ValueType::int32),
                    tag("D1", SignalKind::constant)};
    EXPECT_NE(compile_error(overlap).find("D1 overlaps D0 (int32)"), std::string::npos);

    ScenarioDef unknown_tag;
    unknown_tag.tags = {tag("D0", SignalKind::constant)};
    EventDef e;
    e.at_s = 1;
    e.fault = FaultKind::stuck;
    e.address.text = "D9";
    unknown_tag.events = {e};
    EXPECT_NE(compile_error(unknown_tag).find("D9 is not a tag"), std::string::npos);

    ScenarioDef bad_expr;
    TagDef l = link("D0", "1 + ");
    l.input.pos = {12, 8};
    bad_expr.tags = {l};
    plc::Plc plc;
    auto s = Scenario::compile(bad_expr, plc);
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error().pos.line, 12u);
    EXPECT_EQ(s.error().pos.column, 8u + 5u);  // the quote, then column 5 of "1 + "
}

}  // namespace
}  // namespace fins::scenario
