// Bounded log volume (issue 18 item 7): a line that any peer can cause (a reply dropped
// for a full send buffer, a FINS/TCP connection made or refused, a timeout) is written
// at most once per `log_summary_interval` per kind, with the count of events since the
// last such line; each event on its own goes to the debug level only. Whatever the
// traffic, each kind adds at most one line per interval to the info/warn log.
#pragma once

#include <chrono>
#include <cstdint>

namespace fins::server {

inline constexpr std::chrono::seconds log_summary_interval{10};

class LogSummary {
  public:
    using Clock = std::chrono::steady_clock;

    explicit LogSummary(Clock::duration interval = log_summary_interval) noexcept
        : interval_(interval) {}

    // Counts `events`. Returns how many events the line due now reports (those since
    // the last line, these included), or 0 when no line is due yet. The first event
    // ever is reported at once.
    std::uint64_t note(std::uint64_t events = 1, Clock::time_point now = Clock::now()) noexcept {
        unreported_ += events;
        if (logged_ && now - last_ < interval_) return 0;
        logged_ = true;
        last_ = now;
        const std::uint64_t n = unreported_;
        unreported_ = 0;
        return n;
    }

  private:
    Clock::duration interval_;
    Clock::time_point last_{};
    bool logged_ = false;
    std::uint64_t unreported_ = 0;
};

}  // namespace fins::server
