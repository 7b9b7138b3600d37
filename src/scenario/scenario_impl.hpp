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
    // Direct access, resolved once at compile (bind_direct) so that a tick reads and
    // writes plain words: for a word type in a word area, `words` is its first word and
    // `forced` the forced-bit mask of the same words (null: the area has no forcing); for
    // bool in a word area, `words` is the bit's word and `bit_mask` its bit. Null `words`:
    // through IoMemory (flags, timers' completion flags, ...).
    std::uint16_t* words = nullptr;
    const std::uint16_t* forced = nullptr;
    std::uint16_t bit_mask = 0;
};

// What computing a tag reads of its TagDef, copied at compile next to its state, so that
// a tick touches one small record per tag and not the large TagDef (strings, vectors).
struct TagParams {
    SignalKind kind = SignalKind::constant;
    bool repeat = false;
    double value = 0, min = 0, max = 0, period_s = 1, phase_s = 0, duty = 0.5, step = 1;
    double rate = 0, lag_gain = 0, noise = 0, on_above = 1, off_below = 0;
};

struct TagState {
    TagParams p;
    std::uint32_t reference = 0;
    bool written = false;
    bool previous_input = false;  // counter edges, hysteresis output
    bool has_when = false;        // when.has_value(), kept on the hot cache line
    double state = 0;             // stateful kinds
    std::uint64_t last_raw = 0;   // the words (or bit) the last write left in memory
    const TagDef* def = nullptr;
    std::optional<Expression> input;
    std::optional<Expression> when;
    std::vector<double> delay;  // ring of delay_s / tick_s samples
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
    Impl() = default;
    Impl(const Impl&) = delete;
    Impl& operator=(const Impl&) = delete;
    // Drops the Loop Control Board ITEM sources it set (unless a newer scenario has).
    ~Impl() override;

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

    // ExpressionContext. Impl is final: Expression::run(*this) calls these directly.
    double load(std::uint32_t reference) noexcept override { return read(references[reference]); }
    double normal() noexcept override { return random.normal(); }
    double uniform() noexcept override { return random.uniform(); }
    double time() const noexcept override { return now_s; }
    double tick() const noexcept override { return def.tick_s; }

    // Resolves the direct word access of a located reference (Reference::words).
    void bind_direct(Reference& reference) noexcept;
    // The value a reference's memory holds now, as a double; `raw`: its words packed
    // (first word in the high bits) or its bit, to notice a client's write.
    double read(const Reference& reference, std::uint64_t* raw = nullptr) const noexcept;
    // Writes `value` (rounded and clamped to the type); false when nothing was written.
    bool write(TagState& tag, double value) noexcept;
    double compute(TagState& tag, bool& skip) noexcept;
    void run_events() noexcept;
    void start_event(EventState& event) noexcept;
    void end_event(EventState& event) noexcept;
    void step() noexcept;
};

}  // namespace fins::scenario
