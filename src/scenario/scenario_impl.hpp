// Scenario's private state, shared by scenario.cpp (compile) and scenario_tick.cpp.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "plc/plc.hpp"
#include "scenario/expression.hpp"
#include "scenario/random.hpp"
#include "scenario/scenario.hpp"

namespace fins::scenario {

// A located address and the type its words are read and written as.
struct Reference {
    plc::ElementRange range;
    ValueType type = ValueType::uint16;
    std::int32_t tag = -1;  // the tag writing it, if any
};

struct TagState {
    const TagDef* def = nullptr;
    std::uint32_t reference = 0;
    std::optional<Expression> input;
    std::optional<Expression> when;
    double state = 0;  // stateful kinds
    bool written = false;
    std::array<std::uint8_t, 8> last_bytes{};  // what the last write stored
    bool previous_input = false;               // counter edges, hysteresis output
    std::vector<double> delay;                 // ring of delay_s / tick_s samples
    std::size_t delay_next = 0;
    std::vector<std::uint32_t> faults;  // events that may fault this tag
};

struct EventState {
    const EventDef* def = nullptr;
    std::string name;
    std::int32_t tag = -1;  // value faults
    std::uint8_t area_code = 0;
    bool active = false;
    double start = 0;        // when it started
    double end = 0;          // when it ends (active)
    double next_start = -1;  // -1: never
    double stuck_value = 0;
    bool capture = false;  // stuck: take the value its first tick computes
    plc::OperatingMode previous_mode = plc::OperatingMode::run;
};

struct Scenario::Impl final : ExpressionContext {
    ScenarioDef def;
    plc::Plc* plc = nullptr;
    std::vector<Reference> references;
    std::vector<TagState> tags;        // file order
    std::vector<std::uint32_t> order;  // tags in dependency order
    std::vector<EventState> events;
    Random random;
    TransportFaults transport;
    std::uint64_t tick_count = 0;
    double pending = 0;  // advance() seconds not yet ticked
    double now_s = 0;
    plc::TimePoint host_now{};
    std::uint64_t writes = 0;
    std::uint64_t skipped = 0;

    // ExpressionContext
    double load(std::uint32_t reference) noexcept override;
    double normal() noexcept override { return random.normal(); }
    double uniform() noexcept override { return random.uniform(); }
    double time() const noexcept override { return now_s; }
    double tick() const noexcept override { return def.tick_s; }

    // The value a reference's memory holds now, as a double.
    double read(const Reference& reference,
                std::array<std::uint8_t, 8>* raw = nullptr) const noexcept;
    // Writes `value` (rounded and clamped to the type); false when nothing was written.
    bool write(TagState& tag, double value) noexcept;
    double compute(TagState& tag, bool& skip) noexcept;
    void run_events() noexcept;
    void start_event(EventState& event) noexcept;
    void end_event(EventState& event) noexcept;
    void step() noexcept;
};

}  // namespace fins::scenario
