// A tick in its three phases (scenario.hpp): begin_tick copies the tags' words into the
// scenario's image, compute works on the image only, end_tick copies what changed back.
// What finsd's scenario thread relies on: the phases give what tick() gives, memory is
// untouched until end_tick, a client's write during compute wins, forcing still holds.
#include <gtest/gtest.h>

#include <string>
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

// Every kind that draws random numbers or reads other tags, with a value fault.
ScenarioDef mixed() {
    ScenarioDef def;
    def.seed = 7;
    def.tick_s = 0.1;
    def.virtual_time = true;
    TagDef sine = tag("D100", SignalKind::sine);
    sine.min = 0;
    sine.max = 1000;
    sine.period_s = 3;
    def.tags.push_back(sine);
    TagDef walk = tag("D101", SignalKind::random_walk);
    walk.min = -500;
    walk.max = 500;
    walk.step = 5;
    def.tags.push_back(walk);
    TagDef lag = tag("D102", SignalKind::lag);
    lag.input.text = "D100";
    lag.tau_s = 1;
    lag.noise = 2;
    def.tags.push_back(lag);
    TagDef link = tag("D103", SignalKind::link, ValueType::float32);
    link.input.text = "D101 + D102 / 2 + noise(3)";
    def.tags.push_back(link);
    EventDef spike;
    spike.name = "spike";
    spike.every_s = 0.7;
    spike.duration_s = 0.2;
    spike.fault = FaultKind::spike;
    spike.value = 100;
    spike.address.text = "D101";
    def.events.push_back(spike);
    return def;
}

TEST(ScenarioPhases, BeginComputeEndGiveWhatTickGivesByteForByte) {
    plc::Plc a, b;
    auto sa = compile(mixed(), a);
    auto sb = compile(mixed(), b);
    ASSERT_TRUE(sa && sb);
    for (int i = 0; i < 50; ++i) {
        sa->tick(now);
        sb->begin_tick(now);
        sb->compute();
        sb->end_tick();
    }
    const auto wa = a.memory().words(Region::dm), wb = b.memory().words(Region::dm);
    EXPECT_TRUE(std::equal(wa.begin() + 100, wa.begin() + 105, wb.begin() + 100));
    EXPECT_EQ(sa->status().writes, sb->status().writes);
    EXPECT_EQ(sb->ticks(), 50u);
    EXPECT_NE(a.memory().words(Region::dm)[101], 0);  // it did move
}

TEST(ScenarioPhases, MemoryChangesOnlyAtEndTick) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef c = tag("D10", SignalKind::sawtooth);
    c.max = 100;
    c.period_s = 10;
    def.tags.push_back(c);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    s->start(now);  // t = 0: memory holds the tag at 0
    EXPECT_EQ(s->status().writes, 1u);
    plc.write_access_log().clear();
    s->begin_tick(now + std::chrono::seconds(1));  // another host second: a new record
    s->compute();
    EXPECT_EQ(plc.memory().words(Region::dm)[10], 0);  // computed on the image only
    EXPECT_EQ(plc.write_access_log().size(), 0u);
    EXPECT_EQ(s->status().writes, 1u);
    s->end_tick();
    EXPECT_EQ(plc.memory().words(Region::dm)[10], 1);  // t = 0.1
    EXPECT_EQ(plc.write_access_log().size(), 1u);
    EXPECT_EQ(s->status().writes, 2u);
}

// A client's write between begin_tick and end_tick (while finsd's scenario thread
// computes) is not overwritten, and a stateful tag goes on from it, as from any write.
TEST(ScenarioPhases, AClientWriteDuringComputeWinsAndTheTagAdoptsIt) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef counter = tag("D20", SignalKind::counter);
    counter.input.text = "1";
    counter.rate = 10;  // + 1 a tick of 0.1 s
    def.tags.push_back(counter);
    TagDef follower = tag("D21", SignalKind::link);
    follower.input.text = "D20 * 2";
    def.tags.push_back(follower);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    for (int i = 0; i < 3; ++i)
        s->tick(now);
    EXPECT_EQ(plc.memory().words(Region::dm)[20], 3);
    s->begin_tick(now);
    s->compute();
    plc.memory().words(Region::dm)[20] = 500;  // the HMI writes
    s->end_tick();
    EXPECT_EQ(plc.memory().words(Region::dm)[20], 500);
    EXPECT_EQ(plc.memory().words(Region::dm)[21], 8);  // what the tick computed from 4
    s->tick(now);
    EXPECT_EQ(plc.memory().words(Region::dm)[20], 501);
    EXPECT_EQ(plc.memory().words(Region::dm)[21], 1002);
}

// A bit forced while the tick computes keeps its forced state at end_tick.
TEST(ScenarioPhases, ABitForcedDuringComputeStaysForced) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef word = tag("CIO7", SignalKind::constant, ValueType::uint16);
    word.value = 0x00FF;
    def.tags.push_back(word);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    s->begin_tick(now);
    s->compute();
    plc.memory().force_bit(Region::cio, 7, 2, false);  // forced OFF meanwhile
    s->end_tick();
    EXPECT_EQ(plc.memory().words(Region::cio)[7] & 0x0004, 0);
    s->tick(now);
    EXPECT_EQ(plc.memory().words(Region::cio)[7], 0x00FB);  // the others take the value
}

// Words two references share are one word of the image: a link reading the second word
// of an int32 tag sees what that tag wrote earlier in the same tick.
TEST(ScenarioPhases, OverlappingReferencesShareTheirWordsInTheImage) {
    plc::Plc plc;
    ScenarioDef def;
    TagDef wide = tag("D30", SignalKind::constant, ValueType::int32);
    wide.value = 0x00050007;
    def.tags.push_back(wide);
    TagDef second = tag("D40", SignalKind::link, ValueType::uint16);
    second.input.text = "D31";
    def.tags.push_back(second);
    auto s = compile(def, plc);
    ASSERT_TRUE(s);
    s->tick(now);
    const auto words = int32_to_words(0x00050007);
    EXPECT_EQ(plc.memory().words(Region::dm)[30], words[0]);
    EXPECT_EQ(plc.memory().words(Region::dm)[40], words[1]);
}

// Task flags are not words of an area: a scenario reading one reads it through the CPU
// Unit during compute, so it cannot be computed on another thread.
TEST(ScenarioPhases, OffloadableOnlyWhenEveryTagWordIsInTheImage) {
    plc::Plc plc;
    auto words_only = compile(mixed(), plc);
    ASSERT_TRUE(words_only);
    EXPECT_TRUE(words_only->offloadable());
    ScenarioDef def;
    TagDef flag = tag("D50", SignalKind::link);
    flag.input.text = "TK0";
    def.tags.push_back(flag);
    plc::Plc other;
    auto with_flag = compile(def, other);
    ASSERT_TRUE(with_flag);
    EXPECT_FALSE(with_flag->offloadable());
    with_flag->tick(now);  // and still ticks on the owning thread
    EXPECT_EQ(with_flag->ticks(), 1u);
}

}  // namespace
}  // namespace fins::scenario
