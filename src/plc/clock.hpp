// The CPU Unit clock of CLOCK READ 07 01 / CLOCK WRITE 07 02 (W342 5-3-19, 5-3-20).
//
// The clock is the host's local time (like a PLC whose clock was set from a PC: it
// shows wall-clock time in the host's time zone, following the host's daylight-saving
// changes) plus an offset that 07 02 sets. The day of week is a register of its own,
// kept as a shift from the calendar's day of week, because the CPU Unit "does not check
// the day of week from the day of month" and an omitted day of week keeps its value.
// Both live in a retained Storage section: a PLC rebuilt on the same data directory
// shows the clock it was set to (the CPU Unit's clock is battery-backed).
//
// Range checks of 07 02 (5-3-20 "The PLC automatically checks the range ... If any
// portion of the data is incorrect, the clock will not be set"): month 1-12, day 1 to
// the last day of that month (leap years by the Gregorian rule on the full year),
// hour 0-23, minute 0-59, second 0-59, day of week 0-6. Any failure answers 110C
// (parameter error) and changes nothing.
#pragma once

#include <cstdint>
#include <limits>

#include "fins/commands/clock.hpp"
#include "fins/error.hpp"
#include "plc/io_memory.hpp"
#include "plc/profile.hpp"
#include "plc/storage/storage.hpp"

namespace fins::plc {

// Seconds since 1970-01-01 00:00:00 of a calendar date and time, without a time zone.
using CivilSeconds = std::int64_t;

class Clock {
  public:
    Clock(const Profile& profile, Storage& storage);

    // 07 01: the CPU Unit's date and time when the host's clock reads `now`.
    [[nodiscard]] ClockTime read(TimePoint now) const noexcept;
    // 07 02: sets the clock so that it reads `setting` at `now` (second omitted: 00;
    // day of week omitted: the value read at `now` is kept). 110C, with nothing
    // changed, when a field is out of range; 0000 otherwise.
    EndCode write(const ClockWrite& setting, TimePoint now) noexcept;
    // Changes with every setting of the clock (read() within one host second gives the
    // same reading while it stays the same).
    [[nodiscard]] std::uint64_t version() const noexcept { return version_; }

    // The CPU Unit's time as calendar seconds (for the CLI and tests).
    [[nodiscard]] CivilSeconds civil(TimePoint now) const noexcept;
    // The host's local time as calendar seconds (localtime_r; UTC if that fails).
    [[nodiscard]] static CivilSeconds host_local(TimePoint now) noexcept;
    // Calendar helpers (proleptic Gregorian).
    [[nodiscard]] static CivilSeconds to_civil(int year, unsigned month, unsigned day,
                                               unsigned hour, unsigned minute,
                                               unsigned second) noexcept;
    [[nodiscard]] static unsigned days_in_month(int year, unsigned month) noexcept;
    [[nodiscard]] static unsigned weekday(CivilSeconds t) noexcept;  // 0 Sunday

  private:
    struct State {
        std::int64_t offset_seconds = 0;  // CPU Unit time - host local time
        std::int64_t weekday_shift = 0;   // 0-6, added to the calendar's day of week
    };
    State& state_;
    // The last reading and what it was read from (like the rest of a Plc, used from one
    // thread at a time).
    struct Cached {
        CivilSeconds civil = std::numeric_limits<CivilSeconds>::min();
        std::int64_t weekday_shift = 0;
        ClockTime time{};
    };
    mutable Cached cached_;
    std::uint64_t version_ = 0;
};

}  // namespace fins::plc
