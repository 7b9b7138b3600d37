// Scenario's private state, shared by scenario.cpp (compile) and scenario_tick.cpp.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "plc/plc.hpp"
#include "scenario/expression.hpp"
#include "scenario/random.hpp"
#include "scenario/scenario.hpp"

namespace fins::scenario {

// `v` clamped to T's range and rounded half away from zero, as std::llround, without its
// libm call (4 % of a tick): within 32-bit ranges the whole part converts exactly and the
// rest is exact.
template <typename T>
inline T clamp_round(double v) {
    static_assert(sizeof(T) <= 4);
    const double lo = static_cast<double>(std::numeric_limits<T>::min());
    const double hi = static_cast<double>(std::numeric_limits<T>::max());
    v = std::clamp(v, lo, hi);
    const auto whole = static_cast<std::int64_t>(v);  // toward zero
    const double rest = v - static_cast<double>(whole);
    return static_cast<T>(whole + (rest >= 0.5 ? 1 : 0) - (rest <= -0.5 ? 1 : 0));
}

// A located address and the type its words are read and written as.
struct Reference {
    // The same words in the scenario's image (build_image): what a tick reads and writes
    // (first: the part of a reference a tick reads).
    std::uint16_t* words = nullptr;
    const std::uint16_t* forced = nullptr;
    ValueType type = ValueType::uint16;
    std::uint16_t bit_mask = 0;
    std::int32_t tag = -1;  // the tag writing it, if any
    plc::ElementRange range;
    // Direct access, resolved once at compile (bind_direct): for a word type in a word
    // area, `memory` is its first word in the CPU Unit and `memory_forced` the forced-bit
    // mask of the same words (null: the area has no forcing); for bool in a word area,
    // `memory` is the bit's word and `bit_mask` its bit. Null `memory`: through IoMemory
    // (flags, timers' completion flags, ...).
    std::uint16_t* memory = nullptr;
    const std::uint16_t* memory_forced = nullptr;
};

// A run of consecutive words of one area that the tags touch, copied into the image at
// the start of a tick (with its forced-bit mask) and back at its end.
struct ImageRun {
    std::uint16_t* memory = nullptr;
    const std::uint16_t* forced = nullptr;  // null: the area has no forcing
    std::uint32_t offset = 0;               // in the image
    std::uint32_t size = 0;
};

// Where an expression's program is in Scenario::Impl::code (size 0: no expression).
struct ProgramRef {
    std::uint32_t at = 0;
    std::uint32_t size = 0;
};

// What a tick reads of every tag, one 64-byte cache line: with 1,000 CPU Units of 100
// tags the tags do not stay in the cache between ticks, and each line a tag touches costs
// (a 96-byte record, 1.5 lines a tag, cost a fifth more per tick). What computing a tag
// reads of its TagDef is copied here at compile, in five slots whose meaning the kind
// gives; the rest of a tag is in TagCold, read only when the flags say so.
//   kind                 slot 1     slot 2     slot 3     slot 4     slot 5
//   constant             value
//   sine ... ramp        min        max        period_s   phase_s    duty
//   random_walk          min        max        step       state      last_raw
//   counter              min        max        rate       state      last_raw
//   totaliser                                             state      last_raw
//   lag                  gain       noise                 state      last_raw
//   hysteresis           on_above   off_below
// gain = 1 - exp(-tick_s / tau_s). last_raw: the words (or bit) the tag's last write left
// in the image, for the stateful kinds (`adopts`) to notice a client's write.
struct alignas(64) TagState {
    SignalKind kind = SignalKind::constant;
    bool repeat : 1 = false;          // ramp
    bool adopts : 1 = false;          // stateful: takes a client's write as its state
    bool written : 1 = false;         // written at least once (last_raw is set)
    bool previous_input : 1 = false;  // counter edges, hysteresis output
    bool has_when : 1 = false;        // TagCold::when.size != 0
    bool has_delay : 1 = false;       // !TagCold::delay.empty()
    bool has_faults : 1 = false;      // !TagCold::faults.empty()
    bool word_signed : 1 = false;
    // The tag's one int16 or uint16 word in the image when it has no forced bits to keep
    // (the common tag: written without a look at its Reference), else no_word.
    static constexpr std::uint32_t no_word = 0xFFFFFFFF;
    std::uint32_t word = no_word;
    std::uint32_t reference = 0;
    ProgramRef input;  // counter totaliser lag hysteresis link
    union {
        double min = 0;
        double value;
        double gain;
        double on_above;
    };
    union {
        double max = 0;
        double noise;
        double off_below;
    };
    union {
        double period_s = 0;
        double step;
        double rate;
    };
    union {
        double state = 0;
        double phase_s;
    };
    union {
        std::uint64_t last_raw = 0;
        double duty;
    };
};

static_assert(sizeof(TagState) == 64, "a tick reads TagState for every tag: one cache line");

struct TagCold {
    const TagDef* def = nullptr;  // steps: the schedule
    ProgramRef when;              // the enable condition (TagState::has_when)
    std::vector<double> delay;    // ring of delay_s / tick_s samples
    std::size_t delay_next = 0;
    std::vector<std::uint32_t> faults;  // events that may fault this tag
    // The tag's own clock (TagState::has_when): the ticks that ended with its `when`
    // holding. A time-based kind (sine ... ramp, steps) is computed at active_ticks x
    // tick_s, so it does not advance while off.
    std::uint64_t active_ticks = 0;
};

struct EventState {
    const EventDef* def = nullptr;
    std::string name;
    std::int32_t tag = -1;  // value faults
    // end_code: the area of its address.
    Region region = Region::dm;
    std::uint8_t em_bank = 0;
    bool active = false;
    // Its unit fault is in force (combine_faults): from its start to its end, or for good
    // when a unit fault of duration 0 stays. `started` orders the holders (the newest
    // mode or end code wins); `foreign`: fal/fals/mode, the error was present (or the
    // mode set) by someone else when the first holder started, so the last holder's end
    // leaves it as it found it (the error stays; the mode goes back to `previous_mode`).
    bool holding = false;
    bool foreign = false;
    std::uint64_t started = 0;
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
    std::vector<TagCold> cold;         // parallel to tags
    std::vector<std::uint32_t> order;  // tags in dependency order
    // Every tag's input and when programs, one after the other in dependency order, so a
    // tick reads them as one stream.
    std::vector<Expression::Instruction> code;
    std::vector<EventState> events;
    Random random;
    TransportFaults transport;
    std::uint64_t event_starts = 0;  // EventState::started
    std::uint64_t tick_count = 0;
    // Memory holds the tags at tick_count x tick_s once started (start_refresh computed
    // them at the start time); `elapsed`: the tick being computed ends a tick of time
    // (false for the start's refresh: stateful kinds integrate nothing, draw no step).
    bool started = false;
    bool elapsed = false;
    // The start's refresh after a reload (continue_from): stateful kinds take memory's value
    // as their state.
    bool resuming = false;
    // The host second of the last write access record (end_tick).
    std::int64_t recorded_second = std::numeric_limits<std::int64_t>::min();
    double pending = 0;  // advance() seconds not yet ticked
    double now_s = 0;
    plc::TimePoint host_now{};
    std::uint64_t writes = 0;
    std::uint64_t skipped = 0;
    // The image a tick computes on (contract in scenario.hpp): `image` the words,
    // `image_before` what begin_tick copied in, `image_forced` the forced masks.
    std::vector<ImageRun> runs;
    std::vector<std::uint16_t> image, image_before, image_forced;
    // This tick's compute may run while the owning thread serves requests (begin_tick):
    // keep image_before to tell a client's write from the tick's at end_tick.
    bool concurrent = false;
    bool offloadable = false;  // every tag reference is in the image
    // What compute() counted, folded into writes/skipped by end_tick() (so that status()
    // on the owning thread never reads what a compute on another thread writes).
    std::uint64_t tick_writes = 0;
    std::uint64_t tick_skipped = 0;

    // ExpressionContext. Impl is final: Expression::run(*this) calls these directly.
    double load(std::uint32_t reference) noexcept override { return read(references[reference]); }
    // Expression's load_int16/load_uint16 (the programs' loads of image words, rewritten by
    // bind_loads).
    [[nodiscard]] std::uint16_t word(std::uint32_t index) const noexcept { return image[index]; }
    double normal() noexcept override { return random.normal(); }
    double uniform() noexcept override { return random.uniform(); }
    double time() const noexcept override { return now_s; }
    double tick() const noexcept override { return def.tick_s; }

    // Resolves the direct word access of a located reference (Reference::memory).
    void bind_direct(Reference& reference) noexcept;
    // Lays the directly accessed words of every reference out in runs in the image and
    // points Reference::words there.
    void build_image();
    // After build_image: the programs' loads of one-word integers read the image directly,
    // and every tag on one such word writes it directly (TagState::word).
    void bind_words() noexcept;
    void gather() noexcept;   // memory -> image
    void scatter() noexcept;  // image -> memory, the words the tick changed
    // The value a reference's memory holds now, as a double; `raw`: its words packed
    // (first word in the high bits) or its bit, to notice a client's write.
    double read(const Reference& reference, std::uint64_t* raw = nullptr) const noexcept;
    // read() of a tag's own reference, through TagState::word when it has one.
    double read_own(const TagState& tag, std::uint64_t& raw) const noexcept;
    // Writes `value` (rounded and clamped to the type); false when nothing was written.
    bool write(TagState& tag, double value) noexcept {
        if (!std::isfinite(value)) return false;
        // The common case here, inline: a one-word integer on a word without forcing.
        if (tag.word == TagState::no_word) return write_reference(tag, value);
        const auto word = tag.word_signed
                              ? static_cast<std::uint16_t>(clamp_round<std::int16_t>(value))
                              : clamp_round<std::uint16_t>(value);
        image[tag.word] = word;
        if (tag.adopts) tag.last_raw = word;
        tag.written = true;
        return true;
    }
    // write() of every other tag: through its Reference (forced bits, other types).
    bool write_reference(TagState& tag, double value) noexcept;
    double compute(std::uint32_t index, bool& skip) noexcept;
    // Runs a tag's program (defined in scenario_tick.cpp, with the evaluator).
    double run(ProgramRef program) noexcept;
    // The value faults active on `tag` applied to the value it computed.
    void apply_faults(std::uint32_t index, double& value) noexcept;
    void run_events() noexcept;
    void start_event(EventState& event) noexcept;
    void end_event(EventState& event) noexcept;
    // transport and the scenario's battery cause from every holding event
    // (scenario_events.cpp).
    void combine_faults() noexcept;
    // Another event holding the same fault (fal/fals: the same number), or null.
    EventState* other_holder(const EventState& event) noexcept;
    // The three phases of a tick (Scenario::begin_tick, compute, end_tick). begin_tick
    // moves time one tick on (`elapsed`), or not (the start's refresh), then starts and
    // ends the events due at the new time and copies the image in.
    void begin_tick(bool elapse = true) noexcept;
    // The start's refresh, once: the tags computed at the current time, time unchanged.
    void start_refresh() noexcept;
    // Events placed at a kept time `now_s` (a reload): one-shot events past are not
    // replayed, every_s events next start at their first time after it.
    void place_events() noexcept;
    void compute_tags() noexcept;
    void end_tick() noexcept;
};

}  // namespace fins::scenario
