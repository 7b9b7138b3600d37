// A scenario's events: value faults attach to their tag (applied in the tick), unit
// faults change the CPU Unit or the transport faults (contract in scenario.hpp).
#include <algorithm>
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

std::uint16_t fal_code(const EventDef& e) {
    return static_cast<std::uint16_t>((e.fault == FaultKind::fal ? 0x4100 : 0xC100) + e.number);
}

}  // namespace

// Overlapping events of one kind combine instead of undoing each other (docs/scenarios.md
// "Faults"): every unit fault with an end (and the transport faults and battery of
// duration 0, which stay) holds while in force, and what the CPU Unit or the transport
// shows is worked out from every holder, never from the one event starting or ending.
void Scenario::Impl::start_event(EventState& event) noexcept {
    const EventDef& e = *event.def;
    event.active = true;
    event.start = now_s;
    event.started = ++event_starts;
    // A value fault of duration 0 lasts one tick; a unit fault of duration 0 stays.
    event.end = e.duration_s > 0 ? now_s + e.duration_s
                                 : (is_value_fault(e.fault) ? now_s + def.tick_s : -1);
    const bool timed = event.end >= 0;
    auto& errors = plc->errors();
    switch (e.fault) {
        case FaultKind::stuck:
            event.capture = true;
            break;
        case FaultKind::fal:
        case FaultKind::fals: {
            const auto error_code = fal_code(e);
            const EventState* other = other_holder(event);
            // The first holder notes whether someone else (the ladder, the operator, an
            // event of duration 0) raised the error already; the others inherit it.
            event.foreign = other != nullptr ? other->foreign : errors.is_active(error_code);
            if (e.fault == FaultKind::fal)
                errors.raise_fal(e.number, e.message, host_now);
            else
                errors.raise_fals(e.number, e.message, host_now);
            event.holding = timed;
            break;
        }
        case FaultKind::battery:
            event.holding = true;
            errors.set_battery_cause(plc::ErrorState::battery_cause_scenario, true, host_now);
            break;
        case FaultKind::mode: {
            // The mode to go back to is the one before the first of overlapping events.
            const EventState* other = other_holder(event);
            event.previous_mode = other != nullptr ? other->previous_mode : plc->mode();
            plc->change_mode(operating_mode(e.mode), host_now);
            event.holding = timed;
            break;
        }
        case FaultKind::end_code:
        case FaultKind::offline:
        case FaultKind::latency:
        case FaultKind::drop:
            event.holding = true;
            combine_faults();
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
    if (!timed && !is_value_fault(e.fault)) event.active = false;
}

void Scenario::Impl::end_event(EventState& event) noexcept {
    const EventDef& e = *event.def;
    event.active = false;
    const bool held = event.holding;
    event.holding = false;
    auto& errors = plc->errors();
    switch (e.fault) {
        case FaultKind::fal:
        case FaultKind::fals:
            if (!held) break;
            if (EventState* other = other_holder(event); other != nullptr) {
                // The error stays with the others, and so does whose it was.
                for (auto& o : events)
                    if (o.holding && o.def->fault == e.fault && o.def->number == e.number)
                        o.foreign = o.foreign || event.foreign;
            } else if (!event.foreign) {
                errors.clear(fal_code(e), host_now);
            }
            break;
        case FaultKind::battery:
            if (!held) break;
            if (other_holder(event) == nullptr)
                errors.set_battery_cause(plc::ErrorState::battery_cause_scenario, false, host_now);
            break;
        case FaultKind::mode: {
            if (!held) break;
            // The newest of the mode events still active sets the mode; after the last,
            // the mode from before the first.
            const EventState* newest = nullptr;
            for (const auto& o : events)
                if (o.holding && o.def->fault == FaultKind::mode &&
                    (newest == nullptr || o.started > newest->started))
                    newest = &o;
            if (newest != nullptr) {
                if (plc->mode() != operating_mode(newest->def->mode))
                    plc->change_mode(operating_mode(newest->def->mode), host_now);
            } else {
                plc->change_mode(event.previous_mode, host_now);
            }
            break;
        }
        case FaultKind::end_code:
        case FaultKind::offline:
        case FaultKind::latency:
        case FaultKind::drop:
            combine_faults();
            break;
        default:
            break;
    }
}

void Scenario::Impl::combine_faults() noexcept {
    transport.offline = false;
    transport.latency_ms = 0;
    transport.drop_fraction = 0;
    transport.areas.clear();
    // The newest holder's end code on each area: holders in the order they started.
    std::uint64_t newest_area = 0;
    for (const auto& event : events) {
        if (!event.holding) continue;
        const EventDef& e = *event.def;
        switch (e.fault) {
            case FaultKind::offline:
                transport.offline = true;
                break;
            case FaultKind::latency:
                transport.latency_ms = std::max(transport.latency_ms,
                                                static_cast<std::uint32_t>(std::llround(e.value)));
                break;
            case FaultKind::drop:
                transport.drop_fraction = std::max(transport.drop_fraction, e.value);
                break;
            case FaultKind::end_code:
                newest_area = std::max(newest_area, event.started);
                break;
            default:
                break;
        }
    }
    if (newest_area == 0) return;
    // Few areas and few holders: each holder in start order overwrites its area's code.
    for (std::uint64_t from = 1; from <= newest_area;) {
        const EventState* next = nullptr;
        for (const auto& event : events)
            if (event.holding && event.def->fault == FaultKind::end_code && event.started >= from &&
                (next == nullptr || event.started < next->started))
                next = &event;
        if (next == nullptr) break;
        auto it = std::find_if(transport.areas.begin(), transport.areas.end(),
                               [next](const TransportFaults::AreaFault& a) {
                                   return a.region == next->region && a.em_bank == next->em_bank;
                               });
        if (it == transport.areas.end())
            transport.areas.push_back({next->region, next->em_bank, next->def->end_code});
        else
            it->end_code = next->def->end_code;
        from = next->started + 1;
    }
}

EventState* Scenario::Impl::other_holder(const EventState& event) noexcept {
    const EventDef& e = *event.def;
    for (auto& o : events) {
        if (&o == &event || !o.holding || o.def->fault != e.fault) continue;
        if ((e.fault == FaultKind::fal || e.fault == FaultKind::fals) && o.def->number != e.number)
            continue;
        return &o;
    }
    return nullptr;
}

std::uint16_t TransportFaults::end_code_for(const MemoryAddress& address) const noexcept {
    if (areas.empty()) return 0;
    const auto* segment = find_segment(address.area_code, address.word);
    if (segment == nullptr) return 0;
    for (const auto& a : areas)
        if (a.region == segment->region && a.em_bank == segment->em_bank) return a.end_code;
    return 0;
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
        // Memory holds the tags at time(): a unit fault starts now, a value fault at the
        // next tick, the first that computes with it (its duration counts from there).
        impl_->now_s = time() + (is_value_fault(event.def->fault) ? impl_->def.tick_s : 0.0);
        if (event.active) impl_->end_event(event);
        impl_->start_event(event);
        return true;
    }
    return false;
}

}  // namespace fins::scenario
