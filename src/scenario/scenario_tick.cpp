// One scenario tick in its three phases: events and the image in, every tag in dependency
// order on the image, the image out (contract in scenario.hpp).
// Expressions run on Impl itself (a final class), so their loads are direct calls.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <string_view>
#include <unordered_map>

#include "scenario/expression_eval.hpp"
#include "scenario/scenario_impl.hpp"

namespace fins::scenario {

namespace {

// Slack for comparing a tick's time with event times given in decimal seconds.
constexpr double epsilon = 1e-9;

bool truth(double v) {
    return v != 0.0 && !std::isnan(v);
}

double fraction(double x) {
    return x - std::floor(x);
}

// sin(2 pi f) for f in [0, 1]: the nearest quarter turn, then fdlibm's kernel
// polynomials (Sun, 1993) on at most an eighth of a turn either side: within 1e-15 of
// libm's sin, twice as fast, and the same with every libm. The wave's phase is taken as
// a fraction of the period first, so a long run loses no accuracy to a large argument.
double sin_turns(double f) {
    const auto quarter = static_cast<std::int64_t>(f * 4.0 + 0.5);  // f >= 0: floor
    const double x = (f - static_cast<double>(quarter) * 0.25) * (2 * std::numbers::pi);
    const double z = x * x;
    if ((quarter & 1) == 0) {
        constexpr double s1 = -1.66666666666666324348e-01, s2 = 8.33333333332248946124e-03,
                         s3 = -1.98412698298579493134e-04, s4 = 2.75573137070700676789e-06,
                         s5 = -2.50507602534068634195e-08, s6 = 1.58969099521155010221e-10;
        const double r = s2 + z * (s3 + z * (s4 + z * (s5 + z * s6)));
        const double sin = x + z * x * (s1 + z * r);
        return (quarter & 2) == 0 ? sin : -sin;
    }
    constexpr double c1 = 4.16666666666666019037e-02, c2 = -1.38888888888741095749e-03,
                     c3 = 2.48015872894767294178e-05, c4 = -2.75573143513906633035e-07,
                     c5 = 2.08757232129817482790e-09, c6 = -1.13596475577881948265e-11;
    const double r = z * (c1 + z * (c2 + z * (c3 + z * (c4 + z * (c5 + z * c6)))));
    const double half = 0.5 * z;
    const double w = 1.0 - half;
    const double cos = w + (((1.0 - w) - half) + z * r);
    return (quarter & 2) == 0 ? cos : -cos;
}

}  // namespace

double Scenario::Impl::run(ProgramRef program) noexcept {
    // The most common program, one word read (a lag's setpoint, a counter's input).
    if (program.size == 1 && code[program.at].op == Expression::Op::load_int16)
        return static_cast<std::int16_t>(image[code[program.at].argument]);
    return Expression::run(code.data() + program.at, program.size, *this);
}

double Scenario::Impl::compute(std::uint32_t index, bool& skip) noexcept {
    TagState& tag = tags[index];
    const TagState& d = tag;
    skip = false;
    // A time-based kind reads the scenario time, or with `when` its own clock: the ticks
    // that ended with `when` holding (off, it does not advance).
    double t = now_s;
    if (tag.has_when) {
        TagCold& c = cold[index];
        if (!truth(run(c.when))) {
            skip = true;
            return 0.0;
        }
        if (elapsed) ++c.active_ticks;
        t = static_cast<double>(c.active_ticks) * def.tick_s;
    }
    const double span = d.max - d.min;
    // Stateful kinds take a client's write to the tag as their new state (and after a
    // reload, the value memory holds).
    auto adopt = [&] {
        if (!tag.written && !resuming) return;
        std::uint64_t raw = 0;
        const double held = read_own(tag, raw);
        if ((resuming || raw != tag.last_raw) && std::isfinite(held)) tag.state = held;
    };
    switch (tag.kind) {
        case SignalKind::constant:
            return d.value;
        case SignalKind::sine:
            return d.min + span / 2 + span / 2 * sin_turns(fraction((t + d.phase_s) / d.period_s));
        case SignalKind::square:
            return fraction((t + d.phase_s) / d.period_s) < d.duty ? d.max : d.min;
        case SignalKind::triangle: {
            const double f = fraction((t + d.phase_s) / d.period_s);
            return f < 0.5 ? d.min + span * 2 * f : d.max - span * (2 * f - 1);
        }
        case SignalKind::sawtooth:
            return d.min + span * fraction((t + d.phase_s) / d.period_s);
        case SignalKind::ramp: {
            const double f = d.repeat ? fraction(t / d.period_s) : std::min(t / d.period_s, 1.0);
            return d.min + span * f;
        }
        // The stateful kinds integrate over the tick that just ended (input at its end);
        // the start's refresh (no tick ended) shows their state as it is.
        case SignalKind::random_walk:
            adopt();
            if (elapsed) tag.state = std::clamp(tag.state + d.step * random.normal(), d.min, d.max);
            return tag.state;
        case SignalKind::steps: {
            const TagDef& schedule = *cold[index].def;
            const double at = schedule.repeat_s > 0 ? std::fmod(t, schedule.repeat_s) : t;
            double v = schedule.initial.value_or(schedule.steps.front().second);
            for (const auto& [when, value] : schedule.steps) {
                if (when > at + epsilon) break;
                v = value;
            }
            return v;
        }
        case SignalKind::counter: {
            adopt();
            const bool on = truth(run(tag.input));
            if (!elapsed) {
                // The start: an input already on is no rising edge.
            } else if (d.rate > 0) {
                if (on) tag.state += d.rate * def.tick_s;
            } else if (on && !tag.previous_input) {
                tag.state += 1;
            }
            tag.previous_input = on;
            if (d.max > d.min && tag.state > d.max) tag.state = d.min;
            return d.rate > 0 ? std::floor(tag.state + epsilon) : tag.state;
        }
        case SignalKind::totaliser:
            adopt();
            if (elapsed) tag.state += run(tag.input) * def.tick_s;
            return tag.state;
        case SignalKind::lag: {
            adopt();
            const double setpoint = run(tag.input);
            const double noise = d.noise > 0 ? d.noise * random.normal() : 0.0;
            // gain = 1 - exp(-tick_s / tau_s), computed once at compile.
            if (elapsed && std::isfinite(setpoint)) tag.state += (setpoint - tag.state) * d.gain;
            return tag.state + noise;
        }
        case SignalKind::hysteresis: {
            const double input = run(tag.input);
            if (input >= d.on_above)
                tag.previous_input = true;
            else if (input <= d.off_below)
                tag.previous_input = false;
            return tag.previous_input ? 1.0 : 0.0;
        }
        case SignalKind::link: {
            double v = run(tag.input);
            if (tag.has_delay) {
                TagCold& c = cold[index];
                std::swap(v, c.delay[c.delay_next]);
                c.delay_next = (c.delay_next + 1) % c.delay.size();
            }
            return v;
        }
    }
    return 0.0;
}

void Scenario::Impl::apply_faults(std::uint32_t index, double& value) noexcept {
    for (const auto e : cold[index].faults) {
        EventState& event = events[e];
        if (!event.active) continue;
        const double v = event.def->value;
        switch (event.def->fault) {
            case FaultKind::stuck:
                if (event.capture) event.stuck_value = value;
                event.capture = false;
                value = event.stuck_value;
                break;
            case FaultKind::drift:
                value += v * (now_s - event.start);
                break;
            case FaultKind::spike:
                value += v;
                break;
            case FaultKind::set:
                value = v;
                break;
            case FaultKind::noise:
                value += v * random.normal();
                break;
            default:
                break;
        }
    }
}

void Scenario::Impl::begin_tick(bool elapse) noexcept {
    // Time first, then what is due at the new time: memory ends up holding the tags at
    // tick_count x tick_s, computed with the events of that time.
    if (elapse) ++tick_count;
    elapsed = elapse;
    now_s = static_cast<double>(tick_count) * def.tick_s;
    run_events();
    gather();
    tick_writes = 0;
    tick_skipped = 0;
}

void Scenario::Impl::compute_tags() noexcept {
    // A plant's tags do not stay in the cache between ticks: ask for a tag's lines a few
    // tags ahead of computing it.
    constexpr std::size_t ahead = 8;
    const std::size_t count = order.size();
    for (std::size_t k = 0; k < count; ++k) {
        if (k + ahead < count) {
            __builtin_prefetch(&tags[order[k + ahead]]);  // one line (TagState)
        }
        const std::uint32_t index = order[k];
        TagState& tag = tags[index];
        bool skip = false;
        double value = compute(index, skip);
        if (skip) {
            ++tick_skipped;
            continue;
        }
        if (tag.has_faults) apply_faults(index, value);
        if (write(tag, value))
            ++tick_writes;
        else
            ++tick_skipped;
    }
}

void Scenario::Impl::end_tick() noexcept {
    scatter();
    writes += tick_writes;
    skipped += tick_skipped;
    // A record from node 0.0.0, the CPU Unit itself (what its program writes), at the
    // first tick that writes in each second of the host clock: the log's times are whole
    // seconds, and a plant's units would otherwise each touch their log every tick.
    const std::int64_t second =
        std::chrono::floor<std::chrono::seconds>(host_now).time_since_epoch().count();
    if (tick_writes > 0 && second != recorded_second) {
        plc->write_access_log().record(NodeAddress{0, 0, 0}, CommandCode{0x01, 0x02},
                                       EndCode::normal_completion, host_now);
        recorded_second = second;
    }
    resuming = false;
}

void Scenario::Impl::start_refresh() noexcept {
    if (started) return;
    started = true;
    concurrent = false;
    begin_tick(false);
    compute_tags();
    end_tick();
}

void Scenario::start(plc::TimePoint now) noexcept {
    impl_->host_now = now;
    impl_->start_refresh();
}

bool Scenario::started() const noexcept {
    return impl_->started;
}

void Scenario::continue_from(const Scenario& previous) noexcept {
    Impl& s = *impl_;
    const Impl& p = *previous.impl_;
    if (s.started || !p.started) return;
    // The same tick keeps the count (and what advance() left over); another tick takes
    // the time rounded down to a whole tick of its own.
    if (p.def.tick_s == s.def.tick_s) {
        s.tick_count = p.tick_count;
        s.pending = p.pending;
    } else {
        const double ticks = static_cast<double>(p.tick_count) * p.def.tick_s / s.def.tick_s;
        s.tick_count = static_cast<std::uint64_t>(std::floor(ticks + 1e-6));
    }
    s.now_s = static_cast<double>(s.tick_count) * s.def.tick_s;
    // `when` clocks go on for the tags of the same address.
    std::unordered_map<std::string_view, std::uint64_t> clocks;
    for (std::size_t i = 0; i < p.tags.size(); ++i)
        if (p.tags[i].has_when) clocks.emplace(p.cold[i].def->address.text, p.cold[i].active_ticks);
    for (std::size_t i = 0; i < s.tags.size(); ++i)
        if (s.tags[i].has_when)
            if (const auto it = clocks.find(s.cold[i].def->address.text); it != clocks.end())
                s.cold[i].active_ticks = it->second;
    s.place_events();
    s.resuming = true;
}

void Scenario::Impl::place_events() noexcept {
    for (auto& event : events) {
        if (event.next_start < 0 || event.next_start >= now_s - epsilon) continue;
        if (!event.def->every_s) {
            event.next_start = -1;
            continue;
        }
        const double every = *event.def->every_s;
        event.next_start += std::ceil((now_s - event.next_start) / every - 1e-6) * every;
    }
}

void Scenario::tick(plc::TimePoint now) noexcept {
    impl_->host_now = now;
    impl_->start_refresh();
    impl_->concurrent = false;
    impl_->begin_tick();
    impl_->compute_tags();
    impl_->end_tick();
}

std::array<const void*, Scenario::prefetch_count> Scenario::prefetch_addresses() const noexcept {
    const Impl& s = *impl_;
    std::array<const void*, prefetch_count> out{};
    std::size_t n = 0;
    auto add = [&](const void* p) {
        if (p != nullptr && n < out.size()) out[n++] = p;
    };
    // The scenario's own record where a tick reads it: the vectors' heads, then the tick
    // fields (two lines); the CPU Unit's words begin_tick copies in; the image; the tags
    // and their programs.
    add(&s.tags);
    add(&s.tick_count);
    add(reinterpret_cast<const char*>(&s.tick_count) + 64);
    add(s.runs.data());
    add(s.image.data());
    add(s.tags.data());
    add(s.order.data());
    add(s.code.data());
    for (const auto& run : s.runs)
        add(run.memory);
    return out;
}

bool Scenario::offloadable() const noexcept {
    return impl_->offloadable;
}

void Scenario::begin_tick(plc::TimePoint now) noexcept {
    impl_->host_now = now;
    impl_->start_refresh();
    impl_->concurrent = true;
    impl_->begin_tick();
}

void Scenario::compute() noexcept {
    impl_->compute_tags();
}

void Scenario::end_tick() noexcept {
    impl_->end_tick();
}

std::uint64_t Scenario::plan_advance(double seconds) noexcept {
    if (!(seconds > 0)) return 0;
    Impl& s = *impl_;
    s.pending += seconds;
    // Whole ticks, counted at once (a week at 1 ms is 6e8 ticks: subtracting the tick
    // that often would lose one); within a millionth of a tick counts as whole.
    const double ticks = s.pending / s.def.tick_s;
    double whole = std::floor(ticks);
    if (ticks - whole > 1 - 1e-6) whole += 1;
    s.pending = std::max(0.0, s.pending - whole * s.def.tick_s);
    if (s.pending < s.def.tick_s * 1e-6) s.pending = 0;
    return static_cast<std::uint64_t>(whole);
}

std::uint64_t Scenario::advance(double seconds, plc::TimePoint now) noexcept {
    start(now);
    const auto ticks = plan_advance(seconds);
    for (std::uint64_t i = 0; i < ticks; ++i)
        tick(now);
    return ticks;
}

}  // namespace fins::scenario
