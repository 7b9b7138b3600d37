// The log lines FINS/TCP peers cause, per server (issue 18 item 7): connections made
// and refused, timeouts, envelope errors, foreign sources, confirmations, evictions of
// unfinished handshakes. Each kind goes through a LogSummary (log_summary.hpp, the same
// bound as UDP's dropped replies): every event at debug level, and at most one line per
// interval at its own level, with how many like it came since. 10 s of connection
// churn is a handful of lines, not megabytes.
#pragma once

#include <string>
#include <utility>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "server/sessions/log_summary.hpp"

namespace fins::server {

struct TcpSessionLog {
    LogSummary connected;
    LogSummary refused;
    LogSummary timeouts;
    LogSummary envelope_errors;
    LogSummary foreign_sources;
    LogSummary confirmations;
    LogSummary late_dropped;
    LogSummary evictions;
};

// One event of `kind`: at `level` when its line is due, else at debug.
template <class... Args>
void log_summarised(LogSummary& kind, spdlog::level::level_enum level,
                    fmt::format_string<Args...> format, Args&&... args) {
    const auto n = kind.note();
    if (n == 0) {
        spdlog::debug(format, std::forward<Args>(args)...);
        return;
    }
    if (!spdlog::should_log(level)) return;
    std::string line = fmt::format(format, std::forward<Args>(args)...);
    if (n > 1)
        line +=
            fmt::format(" (and {} more like it since the last such line, at debug level)", n - 1);
    spdlog::log(level, "{}", line);
}

}  // namespace fins::server
