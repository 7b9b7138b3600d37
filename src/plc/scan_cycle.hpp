// The simulated scan cycle: the cycle-time statistics of CYCLE TIME READ 06 20 (W342
// 5-3-18) and the time base of the clock pulses and condition flags (area 07, 5-2-2).
//
// Cycle time base. The CPU Unit cycles on one deterministic timeline counted from the
// Unix epoch: cycle k lasts base + jitter[k mod 16] units of 0.1 ms, where `base`
// depends on the profile (0.5 ms plus 0.1 ms per 10 K words of program area: a bigger
// model stands for a bigger program) and the 16 jitter values (-0.2 .. +0.3 ms) sum to
// zero. So the start of any cycle, and the cycle in progress at any time point, are
// computed in O(1) without timers, and identical runs give identical answers.
//
// Area 07 is refreshed at cycle boundaries: a clock pulse reads what it was at the
// start of the cycle in progress (1-min, 1-s, 0.2-s, 0.1-s, 0.02-s pulses ON for the
// first half of each period). The CPU Unit keeps cycling in PROGRAM mode (overseeing,
// I/O refresh, peripheral servicing; the pulses come from its internal timer), so the
// pulses run in every mode. Condition flags: Always ON is 1, Always OFF 0, and the
// others hold what the last instruction left, which without a user program is 0.
//
// Program execution. Only RUN and MONITOR execute the program; the statistics count
// those cycles only. Operation starts (start(), PROGRAM -> RUN/MONITOR) at the next
// cycle boundary, which also initializes the maximum and minimum (5-3-18 "Comments").
// The CPU Unit powers up (power_on()) when its server starts, and cycles from then on
// whether anyone asks or not: every read (times(), cycles()) is a pure function of the
// time point it is given and of the last power-on, start, stop or initialize, so 06 20,
// the page's status and anything else read the same running unit. 06 20 is refused in
// PROGRAM mode by the 5-1-2 table before it gets here.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>

#include "fins/commands/status.hpp"
#include "plc/io_memory.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc {

class ScanCycle {
  public:
    // Units of the timeline: 0.1 ms, the resolution of 06 20.
    using Ticks = std::int64_t;
    static constexpr std::int64_t microseconds_per_tick = 100;
    static constexpr std::size_t jitter_period = 16;
    static constexpr std::size_t history = 8;  // 5-3-18: average of the last 8 cycles

    ScanCycle(const Profile& profile, Storage& storage);

    // Power-on in RUN mode at `now` (operation starts, as start()); nothing once powered
    // (the power stays on until the process ends: the state is cleared at every start).
    void power_on(TimePoint now) noexcept;
    [[nodiscard]] bool powered() const noexcept;
    // Operation starts (mode leaves PROGRAM): the program runs from the next cycle
    // boundary; the statistics restart. Idempotent while running.
    void start(TimePoint now) noexcept;
    // PROGRAM mode: the program stops; the statistics freeze. Idempotent.
    void stop(TimePoint now) noexcept;
    [[nodiscard]] bool running() const noexcept;
    // 06 20 00: the maximum and minimum restart with the cycle in progress.
    void initialize(TimePoint now) noexcept;

    // 06 20 01 at `now`: average of the last (up to) 8 program cycles completed by then;
    // maximum and minimum since initialize()/start(); 0 where nothing completed (also
    // before power-on, and at a time point before the start: host clock set back). O(1),
    // never allocates.
    [[nodiscard]] CycleTimes times(TimePoint now) const noexcept;
    // Program cycles completed at `now` since operation started.
    [[nodiscard]] std::uint64_t cycles(TimePoint now) const noexcept;

    // ---- the timeline (pure functions of the profile and the time point) ----
    [[nodiscard]] static Ticks base_cycle(const Profile& profile) noexcept;
    // Length of cycle `index` in ticks.
    [[nodiscard]] static Ticks cycle_length(Ticks base, std::uint64_t index) noexcept;
    // Tick at which cycle `index` starts.
    [[nodiscard]] static Ticks cycle_start(Ticks base, std::uint64_t index) noexcept;
    // The cycle in progress at `tick` (ticks before the epoch count as 0).
    [[nodiscard]] static std::uint64_t cycle_at(Ticks base, Ticks tick) noexcept;
    [[nodiscard]] static Ticks to_ticks(TimePoint t) noexcept;

    // Area 07 values for IoMemory (W342 5-2-2).
    [[nodiscard]] static bool clock_pulse(const Profile& profile, ClockPulse pulse,
                                          TimePoint now) noexcept;
    [[nodiscard]] static bool condition_flag(ConditionFlag flag) noexcept;

  private:
    // Cleared at power-on (Retention::cleared): statistics do not survive a restart.
    struct State {
        Ticks latest = 0;               // the last start(), stop() or initialize()
        Ticks stopped_at = 0;           // when stop() ran
        std::uint64_t first = 0;        // first program cycle of this operation
        std::uint64_t stats_first = 0;  // first cycle of maximum/minimum
        std::uint8_t powered = 0;       // power_on(), start() or stop() has run
        std::uint8_t stopped = 0;       // PROGRAM mode
    };
    // The cycle after the last program cycle completed at `now`.
    [[nodiscard]] std::uint64_t end_cycle(Ticks now) const noexcept;

    Ticks base_;
    State& state_;
};

}  // namespace fins::plc
