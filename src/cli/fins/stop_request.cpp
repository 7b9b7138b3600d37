#include "cli/fins/stop_request.hpp"

#ifdef _WIN32
#include <windows.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#else
#include <signal.h>

#include <ctime>
#endif

namespace fins::cli {

using Clock = std::chrono::steady_clock;

#ifdef _WIN32

namespace {

std::mutex stop_mutex;
std::condition_variable stop_changed;
bool stop_flag = false;

BOOL WINAPI on_console_event(DWORD event) {
    if (event != CTRL_C_EVENT && event != CTRL_BREAK_EVENT && event != CTRL_CLOSE_EVENT)
        return FALSE;
    {
        const std::lock_guard lock(stop_mutex);
        stop_flag = true;
    }
    stop_changed.notify_all();
    return TRUE;  // handled: the process ends when the verb returns
}

}  // namespace

StopRequest::StopRequest() {
    ::SetConsoleCtrlHandler(on_console_event, TRUE);
}

StopRequest::~StopRequest() {
    ::SetConsoleCtrlHandler(on_console_event, FALSE);
}

bool StopRequest::requested_before(Clock::time_point until) {
    std::unique_lock lock(stop_mutex);
    return stop_changed.wait_until(lock, until, [] { return stop_flag; });
}

#else

namespace {

sigset_t stop_signals() {
    sigset_t set;
    ::sigemptyset(&set);
    ::sigaddset(&set, SIGINT);
    ::sigaddset(&set, SIGTERM);
    return set;
}

}  // namespace

StopRequest::StopRequest() {
    const auto set = stop_signals();
    ::sigprocmask(SIG_BLOCK, &set, nullptr);
}

StopRequest::~StopRequest() = default;  // the process ends right after the verb

bool StopRequest::requested_before(Clock::time_point until) {
    const auto set = stop_signals();
    // Bounded: each turn either returns or waits out part of the time left.
    for (;;) {
        const auto left = until - Clock::now();
        const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(left).count();
        timespec wait{};
        if (ns > 0) {
            wait.tv_sec = static_cast<std::time_t>(ns / 1'000'000'000);
            wait.tv_nsec = static_cast<long>(ns % 1'000'000'000);
        }
        const int got = ::sigtimedwait(&set, nullptr, &wait);
        if (got == SIGINT || got == SIGTERM) return true;
        if (ns <= 0 || Clock::now() >= until) return false;
    }
}

#endif

}  // namespace fins::cli
