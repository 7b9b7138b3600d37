// One scenario tick: events, then every tag in dependency order (contract in scenario.hpp).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

#include "fins/values.hpp"
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

template <typename T>
T clamp_round(double v) {
    const double lo = static_cast<double>(std::numeric_limits<T>::min());
    const double hi = static_cast<double>(std::numeric_limits<T>::max());
    return static_cast<T>(std::llround(std::clamp(v, lo, hi)));
}

plc::OperatingMode operating_mode(Mode m) {
    switch (m) {
        case Mode::program:
            return plc::OperatingMode::program;
        case Mode::monitor:
            return plc::OperatingMode::monitor;
        case Mode::run:
            return plc::OperatingMode::run;
    }
    return plc::OperatingMode::run;
}

// Calendar date of a count of days since 1970-01-01 (proleptic Gregorian, 400-year eras).
void civil_date(std::int64_t days, std::int64_t& year, unsigned& month, unsigned& day) {
    days += 719468;  // days from 0000-03-01 to 1970-01-01
    const std::int64_t era = (days >= 0 ? days : days - 146096) / 146097;
    const auto day_of_era = static_cast<std::uint64_t>(days - era * 146097);
    const std::uint64_t year_of_era =
        (day_of_era - day_of_era / 1460 + day_of_era / 36524 - day_of_era / 146096) / 365;
    const std::uint64_t day_of_year =
        day_of_era - (365 * year_of_era + year_of_era / 4 - year_of_era / 100);
    const std::uint64_t month_index = (5 * day_of_year + 2) / 153;  // 0 = March
    day = static_cast<unsigned>(day_of_year - (153 * month_index + 2) / 5 + 1);
    month = static_cast<unsigned>(month_index < 10 ? month_index + 3 : month_index - 9);
    year = static_cast<std::int64_t>(year_of_era) + era * 400 + (month <= 2 ? 1 : 0);
}

}  // namespace

double Scenario::Impl::read(const Reference& reference,
                            std::array<std::uint8_t, 8>* raw) const noexcept {
    std::array<std::uint8_t, 8> bytes{};
    ByteWriter out(bytes);
    plc->memory().read(reference.range, out, host_now);
    if (raw != nullptr) *raw = bytes;
    if (reference.type == ValueType::boolean) return bytes[0] != 0 ? 1.0 : 0.0;
    std::array<std::uint16_t, 4> words{};
    const unsigned n = value_words(reference.type);
    for (unsigned i = 0; i < n; ++i)
        words[i] = static_cast<std::uint16_t>((bytes[2 * i] << 8) | bytes[2 * i + 1]);
    const Words w(words.data(), n);
    switch (reference.type) {
        case ValueType::int16:
            return static_cast<std::int16_t>(words[0]);
        case ValueType::uint16:
            return words[0];
        case ValueType::int32:
            return words_to_int32(w).value_or(0);
        case ValueType::uint32:
            return words_to_uint32(w).value_or(0);
        case ValueType::float32:
            return static_cast<double>(words_to_float(w).value_or(0.0f));
        case ValueType::float64:
            return words_to_double(w).value_or(0.0);
        case ValueType::bcd:
            // A word that is not BCD (a client wrote hex) reads as NaN: the tag is skipped.
            return words_to_bcd16(w).has_value() ? *words_to_bcd16(w) : std::nan("");
        case ValueType::boolean:
            break;
    }
    return 0.0;
}

double Scenario::Impl::load(std::uint32_t reference) noexcept {
    return read(references[reference]);
}

bool Scenario::Impl::write(TagState& tag, double value) noexcept {
    const Reference& reference = references[tag.reference];
    if (!std::isfinite(value)) return false;
    std::array<std::uint16_t, 4> words{};
    std::array<std::uint8_t, 8> bytes{};
    std::size_t size = 0;
    switch (reference.type) {
        case ValueType::boolean:
            bytes[0] = truth(value) ? 1 : 0;
            size = 1;
            break;
        case ValueType::int16:
            words[0] = int16_to_words(clamp_round<std::int16_t>(value))[0];
            break;
        case ValueType::uint16:
            words[0] = clamp_round<std::uint16_t>(value);
            break;
        case ValueType::bcd:
            words[0] = bcd16_to_words(
                           static_cast<std::uint16_t>(std::llround(std::clamp(value, 0.0, 9999.0))))
                           .value_or(std::array<std::uint16_t, 1>{})[0];
            break;
        case ValueType::int32: {
            auto w = int32_to_words(clamp_round<std::int32_t>(value));
            std::copy(w.begin(), w.end(), words.begin());
            break;
        }
        case ValueType::uint32: {
            auto w = uint32_to_words(clamp_round<std::uint32_t>(value));
            std::copy(w.begin(), w.end(), words.begin());
            break;
        }
        case ValueType::float32: {
            const double limit = static_cast<double>(std::numeric_limits<float>::max());
            auto w = float_to_words(static_cast<float>(std::clamp(value, -limit, limit)));
            std::copy(w.begin(), w.end(), words.begin());
            break;
        }
        case ValueType::float64: {
            auto w = double_to_words(value);
            std::copy(w.begin(), w.end(), words.begin());
            break;
        }
    }
    if (size == 0) {
        const unsigned n = value_words(reference.type);
        for (unsigned i = 0; i < n; ++i) {
            bytes[2 * i] = static_cast<std::uint8_t>(words[i] >> 8);
            bytes[2 * i + 1] = static_cast<std::uint8_t>(words[i]);
        }
        size = 2 * n;
    }
    // The path of a FINS write: forced bits keep their forced state.
    plc->memory().write(reference.range, Bytes(bytes.data(), size));
    // What memory holds now (a forced bit may differ from what was asked), so that the
    // next tick sees a client's change and not the force.
    read(reference, &tag.last_bytes);
    tag.written = true;
    return true;
}

double Scenario::Impl::compute(TagState& tag, bool& skip) noexcept {
    const TagDef& d = *tag.def;
    skip = false;
    if (tag.when && !truth(tag.when->evaluate(*this))) {
        skip = true;
        return 0.0;
    }
    const double t = now_s;
    const double span = d.max - d.min;
    // Stateful kinds take a client's write to the tag as their new state.
    auto adopt = [&] {
        if (!tag.written) return;
        std::array<std::uint8_t, 8> raw{};
        const double held = read(references[tag.reference], &raw);
        if (raw != tag.last_bytes && std::isfinite(held)) tag.state = held;
    };
    switch (d.kind) {
        case SignalKind::constant:
            return d.value;
        case SignalKind::sine:
            return d.min + span / 2 +
                   span / 2 * std::sin(2 * std::numbers::pi * (t + d.phase_s) / d.period_s);
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
        case SignalKind::random_walk:
            adopt();
            tag.state = std::clamp(tag.state + d.step * random.normal(), d.min, d.max);
            return tag.state;
        case SignalKind::steps: {
            const double at = d.repeat_s > 0 ? std::fmod(t, d.repeat_s) : t;
            double v = d.initial.value_or(d.steps.front().second);
            for (const auto& [when, value] : d.steps) {
                if (when > at + epsilon) break;
                v = value;
            }
            return v;
        }
        case SignalKind::counter: {
            adopt();
            const bool on = truth(tag.input->evaluate(*this));
            if (d.rate > 0) {
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
            tag.state += tag.input->evaluate(*this) * def.tick_s;
            return tag.state;
        case SignalKind::lag: {
            adopt();
            const double setpoint = tag.input->evaluate(*this);
            const double noise = d.noise > 0 ? d.noise * random.normal() : 0.0;
            if (std::isfinite(setpoint))
                tag.state += (setpoint - tag.state) * (1 - std::exp(-def.tick_s / d.tau_s));
            return tag.state + noise;
        }
        case SignalKind::hysteresis: {
            const double input = tag.input->evaluate(*this);
            if (input >= d.on_above)
                tag.previous_input = true;
            else if (input <= d.off_below)
                tag.previous_input = false;
            return tag.previous_input ? 1.0 : 0.0;
        }
        case SignalKind::link: {
            double v = tag.input->evaluate(*this);
            if (!tag.delay.empty()) {
                std::swap(v, tag.delay[tag.delay_next]);
                tag.delay_next = (tag.delay_next + 1) % tag.delay.size();
            }
            return v;
        }
    }
    return 0.0;
}

void Scenario::Impl::start_event(EventState& event) noexcept {
    const EventDef& e = *event.def;
    event.active = true;
    event.start = now_s;
    // A value fault of duration 0 lasts one tick; a unit fault of duration 0 stays.
    event.end = e.duration_s > 0 ? now_s + e.duration_s
                                 : (is_value_fault(e.fault) ? now_s + def.tick_s : -1);
    auto& errors = plc->errors();
    switch (e.fault) {
        case FaultKind::stuck:
            event.capture = true;
            break;
        case FaultKind::fal:
            errors.raise_fal(e.number, e.message, host_now);
            break;
        case FaultKind::fals:
            errors.raise_fals(e.number, e.message, host_now);
            break;
        case FaultKind::battery:
            errors.set_battery_low(true, host_now);
            break;
        case FaultKind::mode:
            event.previous_mode = plc->mode();
            plc->change_mode(operating_mode(e.mode), host_now);
            break;
        case FaultKind::end_code:
            transport.area_code = event.area_code;
            transport.end_code = e.end_code;
            break;
        case FaultKind::offline:
            transport.offline = true;
            break;
        case FaultKind::latency:
            transport.latency_ms = static_cast<std::uint32_t>(std::llround(e.value));
            break;
        case FaultKind::drop:
            transport.drop_fraction = e.value;
            break;
        case FaultKind::clock_jump: {
            const std::int64_t c = plc->clock().civil(host_now) + std::llround(e.value);
            const std::int64_t days = (c >= 0 ? c : c - 86399) / 86400;
            const std::int64_t second_of_day = c - days * 86400;
            std::int64_t year = 0;
            unsigned month = 1, day = 1;
            civil_date(days, year, month, day);
            ClockWrite w;
            w.year = static_cast<std::uint8_t>(((year % 100) + 100) % 100);
            w.month = static_cast<std::uint8_t>(month);
            w.day = static_cast<std::uint8_t>(day);
            w.hour = static_cast<std::uint8_t>(second_of_day / 3600);
            w.minute = static_cast<std::uint8_t>(second_of_day / 60 % 60);
            w.second = static_cast<std::uint8_t>(second_of_day % 60);
            w.day_of_week = static_cast<std::uint8_t>(plc::Clock::weekday(c));
            plc->clock().write(w, host_now);
            event.active = false;
            break;
        }
        default:
            break;
    }
    if (event.end < 0 && !is_value_fault(e.fault)) event.active = false;
}

void Scenario::Impl::end_event(EventState& event) noexcept {
    const EventDef& e = *event.def;
    event.active = false;
    auto& errors = plc->errors();
    switch (e.fault) {
        case FaultKind::fal:
            errors.clear(static_cast<std::uint16_t>(0x4100 + e.number), host_now);
            break;
        case FaultKind::fals:
            errors.clear(static_cast<std::uint16_t>(0xC100 + e.number), host_now);
            break;
        case FaultKind::battery:
            errors.set_battery_low(false, host_now);
            break;
        case FaultKind::mode:
            plc->change_mode(event.previous_mode, host_now);
            break;
        case FaultKind::end_code:
            transport.area_code = 0;
            transport.end_code = 0;
            break;
        case FaultKind::offline:
            transport.offline = false;
            break;
        case FaultKind::latency:
            transport.latency_ms = 0;
            break;
        case FaultKind::drop:
            transport.drop_fraction = 0;
            break;
        default:
            break;
    }
}

void Scenario::Impl::run_events() noexcept {
    for (auto& event : events) {
        if (event.active && event.end >= 0 && now_s >= event.end - epsilon) end_event(event);
        if (event.next_start >= 0 && now_s >= event.next_start - epsilon) {
            if (!event.active) start_event(event);
            if (event.def->every_s) {
                while (event.next_start <= now_s + epsilon)
                    event.next_start += *event.def->every_s;
            } else {
                event.next_start = -1;
            }
        }
    }
}

void Scenario::Impl::step() noexcept {
    now_s = static_cast<double>(tick_count) * def.tick_s;
    run_events();
    bool wrote = false;
    for (const auto index : order) {
        TagState& tag = tags[index];
        bool skip = false;
        double value = compute(tag, skip);
        if (skip) {
            ++skipped;
            continue;
        }
        for (const auto e : tag.faults) {
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
        if (write(tag, value)) {
            ++writes;
            wrote = true;
        } else {
            ++skipped;
        }
    }
    // One record per tick from node 0.0.0, the CPU Unit itself (what its program writes).
    if (wrote)
        plc->write_access_log().record(NodeAddress{0, 0, 0}, CommandCode{0x01, 0x02},
                                       EndCode::normal_completion, host_now);
    ++tick_count;
    // Events whose duration runs out at the new time end now: after advance(5) an event
    // of 0-5 s is over (a unit fault is cleared before the next request is served).
    now_s = static_cast<double>(tick_count) * def.tick_s;
    for (auto& event : events)
        if (event.active && event.end >= 0 && now_s >= event.end - epsilon) end_event(event);
}

void Scenario::tick(plc::TimePoint now) noexcept {
    impl_->host_now = now;
    impl_->step();
}

std::uint64_t Scenario::advance(double seconds, plc::TimePoint now) noexcept {
    if (!(seconds > 0)) return 0;
    impl_->pending += seconds;
    std::uint64_t ran = 0;
    while (impl_->pending >= impl_->def.tick_s - epsilon) {
        impl_->pending -= impl_->def.tick_s;
        tick(now);
        ++ran;
    }
    if (impl_->pending < 0) impl_->pending = 0;
    return ran;
}

bool Scenario::trigger(std::string_view name, plc::TimePoint now) noexcept {
    for (auto& event : impl_->events) {
        if (event.name != name) continue;
        impl_->host_now = now;
        impl_->now_s = time();
        if (event.active) impl_->end_event(event);
        impl_->start_event(event);
        return true;
    }
    return false;
}

}  // namespace fins::scenario
