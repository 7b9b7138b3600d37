// A scenario's events: value faults attach to their tag (applied in the tick), unit
// faults change the CPU Unit or the transport faults (contract in scenario.hpp).
#include <cmath>

#include "scenario/scenario_impl.hpp"

namespace fins::scenario {

namespace {

// Slack for comparing a tick's time with event times given in decimal seconds.
constexpr double epsilon = 1e-9;

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
