// The simulated scan cycle (see scan_cycle.hpp for the model).
#include "plc/scan_cycle.hpp"

#include <algorithm>

namespace fins::plc {

namespace {

using Ticks = ScanCycle::Ticks;
constexpr auto period = ScanCycle::jitter_period;

// Deviation of each cycle from the base, in ticks; the sum is zero so that 16 cycles
// always last 16 x base and cycle starts are computed by division.
constexpr std::array<Ticks, period> jitter{0, 1, -1, 2, 0, -2, 1, 0, -1, 3, -2, 0, 1, -1, 0, -1};
// Sum of jitter[0 .. j).
constexpr std::array<Ticks, period + 1> jitter_prefix = [] {
    std::array<Ticks, period + 1> p{};
    for (std::size_t j = 0; j < period; ++j)
        p[j + 1] = p[j] + jitter[j];
    return p;
}();
static_assert(jitter_prefix[period] == 0, "the jitter must sum to zero");

constexpr Ticks min_base = 5;      // 0.5 ms: every cycle stays >= 0.3 ms
constexpr Ticks max_base = 10000;  // 1 s

// Clock pulse periods in microseconds: 1 min, 1 s, 0.2 s, 0.1 s, 0.02 s (5-2-2, area 07).
constexpr std::array<std::int64_t, clock_pulse_count> pulse_periods{60'000'000, 1'000'000, 200'000,
                                                                    100'000, 20'000};

constexpr Ticks offset_in_block(Ticks base, std::size_t j) noexcept {
    return static_cast<Ticks>(j) * base + jitter_prefix[j];
}

}  // namespace

ScanCycle::ScanCycle(const Profile& profile, Storage& storage)
    : base_(base_cycle(profile)), state_(storage.object<State>("scan_cycle", Retention::cleared)) {}

Ticks ScanCycle::base_cycle(const Profile& profile) noexcept {
    return std::clamp<Ticks>(min_base + profile.program_kwords / 10, min_base, max_base);
}

Ticks ScanCycle::cycle_length(Ticks base, std::uint64_t index) noexcept {
    return base + jitter[index % period];
}

Ticks ScanCycle::cycle_start(Ticks base, std::uint64_t index) noexcept {
    const auto block = static_cast<Ticks>(index / period);
    return block * (base * static_cast<Ticks>(period)) + offset_in_block(base, index % period);
}

std::uint64_t ScanCycle::cycle_at(Ticks base, Ticks tick) noexcept {
    if (tick < 0) tick = 0;
    const Ticks block_length = base * static_cast<Ticks>(period);
    const auto block = static_cast<std::uint64_t>(tick / block_length);
    const Ticks rest = tick % block_length;
    std::size_t j = period - 1;  // bounded: at most 15 steps
    while (j > 0 && offset_in_block(base, j) > rest)
        --j;
    return block * period + j;
}

Ticks ScanCycle::to_ticks(TimePoint t) noexcept {
    const auto us = std::chrono::duration_cast<std::chrono::microseconds>(t.time_since_epoch());
    return us.count() < 0 ? 0 : us.count() / microseconds_per_tick;
}

bool ScanCycle::clock_pulse(const Profile& profile, ClockPulse pulse, TimePoint now) noexcept {
    const auto i = static_cast<std::size_t>(pulse);
    if (i >= pulse_periods.size()) return false;
    const Ticks base = base_cycle(profile);
    // The value refreshed at the start of the cycle in progress.
    const Ticks refreshed = cycle_start(base, cycle_at(base, to_ticks(now)));
    const std::int64_t us = refreshed * microseconds_per_tick;
    return us % pulse_periods[i] < pulse_periods[i] / 2;
}

bool ScanCycle::condition_flag(ConditionFlag flag) noexcept {
    return flag == ConditionFlag::always_on;
}

void ScanCycle::power_on(TimePoint now) noexcept {
    if (state_.powered == 0) start(now);  // power-on in RUN mode (plc.hpp)
}

bool ScanCycle::powered() const noexcept {
    return state_.powered != 0;
}

void ScanCycle::start(TimePoint now) noexcept {
    const Ticks tick = to_ticks(now);
    state_.latest = tick;
    if (state_.powered != 0 && state_.stopped == 0) return;  // already running
    state_.powered = 1;
    state_.stopped = 0;
    state_.first = cycle_at(base_, tick) + 1;
    state_.stats_first = state_.first;
}

void ScanCycle::stop(TimePoint now) noexcept {
    const Ticks tick = to_ticks(now);
    state_.latest = tick;
    if (state_.stopped != 0) return;
    // Powered up in PROGRAM mode: no program cycle has run.
    if (state_.powered == 0) state_.first = state_.stats_first = cycle_at(base_, tick) + 1;
    state_.powered = 1;
    state_.stopped = 1;
    state_.stopped_at = tick;
}

bool ScanCycle::running() const noexcept {
    return state_.stopped == 0;
}

void ScanCycle::initialize(TimePoint now) noexcept {
    state_.latest = to_ticks(now);
    state_.stats_first = std::max(state_.first, cycle_at(base_, state_.latest));
}

std::uint64_t ScanCycle::end_cycle(Ticks now) const noexcept {
    const Ticks until = state_.stopped != 0 ? std::min(now, state_.stopped_at) : now;
    return cycle_at(base_, until);
}

std::uint64_t ScanCycle::cycles(TimePoint now) const noexcept {
    if (state_.powered == 0) return 0;
    const auto end = end_cycle(to_ticks(now));
    return end > state_.first ? end - state_.first : 0;
}

CycleTimes ScanCycle::times(TimePoint now) const noexcept {
    CycleTimes t;
    if (state_.powered == 0) return t;
    const auto end = end_cycle(to_ticks(now));
    if (end <= state_.first) return t;
    const auto m = std::min<std::uint64_t>(end - state_.first, history);
    const Ticks span = cycle_start(base_, end) - cycle_start(base_, end - m);
    t.average = static_cast<std::uint32_t>(span / static_cast<Ticks>(m));

    const auto from = std::max(state_.stats_first, state_.first);
    if (end <= from) return t;
    // A full jitter period holds every cycle length; fewer cycles are walked (<= 15).
    Ticks longest = 0;
    Ticks shortest = 0;
    if (end - from >= period) {
        longest = base_ + *std::max_element(jitter.begin(), jitter.end());
        shortest = base_ + *std::min_element(jitter.begin(), jitter.end());
    } else {
        longest = shortest = cycle_length(base_, from);
        for (auto k = from + 1; k < end; ++k) {
            longest = std::max(longest, cycle_length(base_, k));
            shortest = std::min(shortest, cycle_length(base_, k));
        }
    }
    t.maximum = static_cast<std::uint32_t>(longest);
    t.minimum = static_cast<std::uint32_t>(shortest);
    return t;
}

}  // namespace fins::plc
