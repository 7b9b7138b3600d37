// When a poller acts: the drift-free tick grid of a group, the start phases spread over
// the interval, and the back-off with full jitter before an offline PLC (or a lost
// broker) is tried again. Pure: the time is always passed in, so the tests use an
// invented clock.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <random>

namespace fins::bridge {

using PollClock = std::chrono::steady_clock;

// Tick k of a group is at start + phase x interval + k x interval, whatever the ticks
// before it cost: lateness never accumulates. A tick that comes when the grid point
// after it has already passed skips the missed points and counts them.
//
// With an `align`ment the first tick is rounded up to a multiple of it on the clock
// (and an interval that is a multiple of it keeps every tick there): grids started at
// different instants with nearby phases then share their ticks' time points, and the
// loop wakes once for all of them (tick_alignment() below).
class TickGrid {
  public:
    using Clock = std::chrono::steady_clock;
    TickGrid() = default;
    TickGrid(Clock::time_point start, Clock::duration interval, double phase,
             Clock::duration align = Clock::duration::zero()) noexcept
        : interval_(interval),
          next_(round_up(start + std::chrono::duration_cast<Clock::duration>(interval * phase),
                         align)) {}

    // The time the next tick is due.
    [[nodiscard]] Clock::time_point next() const noexcept { return next_; }
    // The tick due at next() runs at `now`: moves next() to the first grid point after
    // `now` and returns how many grid points were skipped (overruns).
    std::uint64_t advance(Clock::time_point now) noexcept {
        next_ += interval_;
        if (next_ > now) return 0;
        const auto missed = (now - next_) / interval_ + 1;
        next_ += interval_ * missed;
        return static_cast<std::uint64_t>(missed);
    }

  private:
    static Clock::time_point round_up(Clock::time_point t, Clock::duration align) noexcept {
        if (align <= Clock::duration::zero()) return t;
        const auto rest = t.time_since_epoch() % align;
        return rest == Clock::duration::zero() ? t : t + (align - rest);
    }

    Clock::duration interval_{1};
    Clock::time_point next_{};
};

// The alignment of a group's ticks (the poller's TickGrid): 5 ms, or a twentieth of a
// shorter interval, so that an interval keeps at least 20 time points for the phases to
// spread over. 1,000 PLCs every 100 ms then wake the loop 20 times per interval, about 50
// PLCs at a time, instead of 1,000 times: their answers come back together, are drained
// in fewer calls, and their MQTT messages share TCP segments (docs/benchmarks.md).
constexpr std::chrono::steady_clock::duration tick_alignment(
    std::chrono::steady_clock::duration interval) noexcept {
    constexpr std::chrono::steady_clock::duration most = std::chrono::milliseconds(5);
    return interval / 20 < most ? interval / 20 : most;
}

// The start phase in [0, 1) of the index-th poller: golden-ratio steps, so that any
// number of pollers spreads evenly over the interval (no two within 1/n of each other's
// neighbours by more than a factor of ~2.6, whatever n is).
double spread_phase(std::size_t index) noexcept;

// Full jitter: the n-th retry (n = 0, 1, ...) waits uniform(0, min(max, min x 2^n)), so
// that a thousand PLCs (or bridges) coming back do not retry in step.
class Backoff {
  public:
    Backoff(std::chrono::milliseconds min, std::chrono::milliseconds max,
            std::uint64_t seed) noexcept
        : min_(min), max_(max), random_(seed) {}
    // The wait before the next try; each call counts one more failed try.
    std::chrono::milliseconds next();
    // The upper bound of the wait after `attempt` failed tries.
    [[nodiscard]] std::chrono::milliseconds cap(unsigned attempt) const noexcept;
    void reset() noexcept { attempt_ = 0; }
    [[nodiscard]] unsigned attempt() const noexcept { return attempt_; }

  private:
    std::chrono::milliseconds min_;
    std::chrono::milliseconds max_;
    std::mt19937_64 random_;
    unsigned attempt_ = 0;
};

}  // namespace fins::bridge
