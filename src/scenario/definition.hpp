// A scenario as its file states it: tags (signals and links), inputs and events. Data only;
// the loader (src/finsd/config_scenario.cpp) fills it from TOML, Scenario::compile()
// checks it against a CPU Unit and turns it into something that runs. Every field the
// file can get wrong carries the position of its TOML value so that compile errors point
// at file:line:col.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace fins::scenario {

// A 1-based position in one of the scenario's source files (`source`: an index the
// loader keeps; a [scenario] table may include a file); line 0 = unknown.
struct SourcePos {
    std::uint32_t line = 0;
    std::uint32_t column = 0;
    std::uint32_t source = 0;
};

// The value types of `fins --as`: how a tag's value sits in PLC words (fins/values.hpp).
enum class ValueType : std::uint8_t {
    int16,
    uint16,
    int32,
    uint32,
    float32,
    float64,
    bcd,
    boolean
};

// "int16" "uint16" "int32" "uint32" "float" (or "float32") "double" (or "float64") "bcd"
// (one word, 0-9999) "bool" (a bit address).
std::optional<ValueType> parse_value_type(std::string_view name);
std::string_view value_type_name(ValueType type);
// Words per value; 0 for bool (one bit).
unsigned value_words(ValueType type);

// A string value of the file: an expression or an address, with where it starts (the
// position of its opening quote) and, when the loader has it, the value as written in
// the file (`raw`: from its opening quote to its closing one, escapes undone by TOML).
struct Text {
    std::string text;
    SourcePos pos;
    std::string raw;

    // Where character `column` of line `line` of `text` (1-based, counted in characters,
    // not bytes) is in the file: through `raw` across a multi-line string's lines, its
    // skipped first line break, escape sequences (\n, \t, \", \u00E9 ...) and
    // line-ending backslashes; without `raw`, counted from the opening quote as if the
    // value held no escapes.
    [[nodiscard]] SourcePos position(std::uint32_t line, std::uint32_t column) const;
};

// The message for an address `text` that fins::parse_address refused with `error`: a
// word, bit or bank beyond its area names the area's range ("D40000 is out of range:
// D0-D32767").
std::string address_error(std::string_view text, const std::error_code& error);

enum class SignalKind : std::uint8_t {
    constant,     // value
    sine,         // (min+max)/2 + (max-min)/2 * sin(2 pi (t + phase_s) / period_s)
    square,       // max for the first duty * period_s of each period, else min
    triangle,     // min -> max -> min over each period
    sawtooth,     // min -> max over each period, then back to min
    ramp,         // min -> max over period_s, then holds max (repeat: starts again)
    random_walk,  // each tick + normal(0, step), kept within [min, max], starts at initial
    steps,        // steps = [[t, value], ...]; repeat_s > 0 restarts the schedule
    counter,      // + 1 on each rising edge of input (or + rate per second while input);
                  // back to min after max when max > min
    totaliser,    // + input * dt each tick
    lag,          // first order toward input (the setpoint) with time constant tau_s, + noise
    hysteresis,   // 1 once input >= on_above, 0 once input <= off_below
    link,         // input (the expression), when, delay_s
};
std::optional<SignalKind> parse_signal_kind(std::string_view name);
std::string_view signal_kind_name(SignalKind kind);

struct TagDef {
    SourcePos pos;  // the [[scenario.signal]] / [[scenario.link]] table
    Text address;
    ValueType type = ValueType::int16;
    SignalKind kind = SignalKind::constant;
    double value = 0, min = 0, max = 0, period_s = 1, phase_s = 0, duty = 0.5, step = 1;
    double rate = 0, tau_s = 1, noise = 0, on_above = 1, off_below = 0, delay_s = 0;
    std::optional<double> initial;
    bool repeat = false;
    std::vector<std::pair<double, double>> steps;  // (t, value), t ascending
    double repeat_s = 0;
    Text input;  // the expression of link / counter / totaliser / lag / hysteresis
    Text when;   // empty: always
};

// An address the scenario reads but does not write (an HMI's command bit or setpoint),
// with the type its words are read as. Undeclared references read a word as uint16 and
// a bit as bool.
struct InputDef {
    SourcePos pos;
    Text address;
    ValueType type = ValueType::uint16;
};

enum class FaultKind : std::uint8_t {
    // value faults on one tag (address)
    stuck,  // keeps the value it had when the event started
    drift,  // + value per second since the start
    spike,  // + value (for one tick when duration_s is 0)
    set,    // = value
    noise,  // + normal(0, value)
    // unit faults
    fal,         // FAL number (message); cleared at the end
    fals,        // FALS number (message); stays until ERROR CLEAR (like the real one)
    battery,     // battery low; replaced at the end
    mode,        // mode = "program" | "monitor" | "run"; the old mode back at the end
    end_code,    // every memory area command on address's area answers end_code
    offline,     // datagrams ignored, TCP connections refused
    latency,     // answers delayed by value ms
    drop,        // a fraction `value` (0-1) of answers never sent
    clock_jump,  // the CPU Unit clock moves by value seconds
};
std::optional<FaultKind> parse_fault_kind(std::string_view name);
std::string_view fault_kind_name(FaultKind kind);
[[nodiscard]] bool is_value_fault(FaultKind kind);

enum class Mode : std::uint8_t { program, monitor, run };

struct EventDef {
    SourcePos pos;
    std::string name;  // for `finsd ctl scenario trigger NAME`; "" = event-N (1-based)
    std::optional<double> at_s;
    std::optional<double> every_s;  // first at at_s (or every_s), then every every_s
    double duration_s = 0;
    FaultKind fault = FaultKind::set;
    Text address;  // value faults: the tag; end_code: any address of the area
    double value = 0;
    std::uint16_t number = 1;  // FAL/FALS
    std::string message;
    Mode mode = Mode::program;
    std::uint16_t end_code = 0;
};

// An ITEM of a Loop Control Board function block that 02 40 answers from memory: the
// word(s) at `address`, usually a tag of the scenario (the loop's PV, SP or MV). Only on
// a profile with the board (cs1h-lcb).
struct LoopItemDef {
    SourcePos pos;
    std::int64_t block = -1;
    std::int64_t item = -1;
    Text address;
};

inline constexpr std::size_t max_tags = 100000;
inline constexpr std::size_t max_events = 10000;
inline constexpr double max_delay_s = 3600;
inline constexpr std::size_t max_delay_samples = 100000;

struct ScenarioDef {
    std::uint64_t seed = 0;
    double tick_s = 0.1;
    bool virtual_time = false;  // time moves only by advance()
    double time_scale = 1.0;    // real time: scenario seconds per wall-clock second
    std::vector<TagDef> tags;   // in file order: signals first, then links
    std::vector<InputDef> inputs;
    std::vector<EventDef> events;
    std::vector<LoopItemDef> loop_items;
};

}  // namespace fins::scenario
