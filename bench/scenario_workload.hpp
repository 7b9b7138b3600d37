// The scenario of fins_scenario_tick and fins_scenario_load: T tags on D1000 onward, a
// quarter sines, a quarter random walks, a quarter lags toward a setpoint (the sine two
// tags before), a quarter links reading two other tags with noise(). Virtual time (the
// load bench turns it to real time).
#pragma once

#include <cstdint>
#include <string>

#include "scenario/definition.hpp"

namespace fins_bench {

inline fins::scenario::ScenarioDef scenario_workload(unsigned tags, unsigned tick_ms,
                                                     std::uint64_t seed) {
    using namespace fins::scenario;
    ScenarioDef def;
    def.seed = seed;
    def.tick_s = tick_ms / 1000.0;
    def.virtual_time = true;
    for (unsigned i = 0; i < tags; ++i) {
        TagDef t;
        t.address.text = "D" + std::to_string(1000 + i);
        t.type = ValueType::int16;
        switch (i % 4) {
            case 0:
                t.kind = SignalKind::sine;
                t.min = 0;
                t.max = 1000;
                t.period_s = 10 + i;
                break;
            case 1:
                t.kind = SignalKind::random_walk;
                t.min = -500;
                t.max = 500;
                t.step = 3;
                break;
            case 2:
                t.kind = SignalKind::lag;
                t.input.text = "D" + std::to_string(1000 + i - 2);
                t.tau_s = 5;
                t.noise = 1;
                break;
            default:
                t.kind = SignalKind::link;
                t.input.text = "D" + std::to_string(1000 + i - 3) + " + D" +
                               std::to_string(1000 + i - 2) + " / 2 + noise(2)";
                break;
        }
        def.tags.push_back(std::move(t));
    }
    return def;
}

}  // namespace fins_bench
