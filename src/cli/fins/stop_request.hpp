#pragma once
// Ctrl-C (and SIGTERM on Linux) as a request to stop between two steps of a long verb
// (`fins watch`), never in the middle of one: a request is never cut half way and the
// output ends on a whole line.
//   Linux: SIGINT and SIGTERM are blocked while the object lives (before any thread
//   starts, so every thread inherits the mask) and taken with sigtimedwait.
//   Windows: a console control handler (Ctrl-C, Ctrl-Break, the window closing) sets a
//   flag the wait sees.
#include <chrono>

namespace fins::cli {

class StopRequest {
  public:
    StopRequest();
    ~StopRequest();
    StopRequest(const StopRequest&) = delete;
    StopRequest& operator=(const StopRequest&) = delete;

    // Waits until `until` unless a stop is requested first: true when one was.
    bool requested_before(std::chrono::steady_clock::time_point until);
};

}  // namespace fins::cli
