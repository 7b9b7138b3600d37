// StateFileGuard (contract in storage_guard.hpp).
// Linux (SIGBUS); Windows: storage_guard_win.cpp.
#ifndef _WIN32
#include "plc/storage/storage_guard.hpp"

#include <signal.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <mutex>

namespace fins::plc {

namespace {

struct Slot {
    // Set last on registration, cleared first on removal: the handler reads the rest
    // only while it holds the file.
    std::atomic<bool> used{false};
    const std::pair<void*, std::size_t>* ranges = nullptr;
    std::size_t count = 0;
    const char* message = nullptr;
    std::size_t message_size = 0;
};

std::array<Slot, StateFileGuard::capacity> slots;
std::atomic<std::size_t> slots_in_use{0};  // high-water mark: the handler scans no further
std::mutex registration;                   // registrations only; never taken by the handler
struct sigaction previous {};
bool installed = false;

bool holds(const Slot& s, const char* address) noexcept {
    for (std::size_t i = 0; i < s.count; ++i) {
        const char* begin = static_cast<const char*>(s.ranges[i].first);
        if (address >= begin && address < begin + s.ranges[i].second) return true;
    }
    return false;
}

void on_sigbus(int signal, siginfo_t* info, void* context) {
    const char* address = static_cast<const char*>(info->si_addr);
    const std::size_t n = slots_in_use.load(std::memory_order_acquire);
    for (std::size_t i = 0; i < n; ++i) {
        const Slot& s = slots[i];
        if (!s.used.load(std::memory_order_acquire) || !holds(s, address)) continue;
        [[maybe_unused]] const auto written = ::write(STDERR_FILENO, s.message, s.message_size);
        ::_exit(state_file_lost_exit_code);
    }
    // Not a state file: whoever handled SIGBUS before us, or the default action when
    // the faulting access runs again.
    if ((previous.sa_flags & SA_SIGINFO) != 0 && previous.sa_sigaction != nullptr) {
        previous.sa_sigaction(signal, info, context);
        return;
    }
    if (previous.sa_handler != SIG_DFL && previous.sa_handler != SIG_IGN &&
        previous.sa_handler != nullptr) {
        previous.sa_handler(signal);
        return;
    }
    struct sigaction fallback {};
    fallback.sa_handler = SIG_DFL;
    ::sigaction(SIGBUS, &fallback, nullptr);
}

void install() {
    if (installed) return;
    struct sigaction action {};
    action.sa_sigaction = on_sigbus;
    action.sa_flags = SA_SIGINFO;
    sigemptyset(&action.sa_mask);
    if (::sigaction(SIGBUS, &action, &previous) == 0) installed = true;
}

}  // namespace

std::string state_file_lost_message(const std::string& path) {
    return "finsd: state file " + path +
           " shrank while finsd ran (truncated or emptied from outside): its retained "
           "memory is gone; exiting with code " +
           std::to_string(state_file_lost_exit_code) +
           " without writing to it (restore it, or start with --reset-state)\n";
}

StateFileGuard::StateFileGuard(std::span<const std::pair<void*, std::size_t>> ranges,
                               const std::string& path)
    : message_(state_file_lost_message(path)) {
    const std::lock_guard lock(registration);
    install();
    const std::size_t n = slots_in_use.load(std::memory_order_relaxed);
    for (std::size_t i = 0; i < slots.size(); ++i) {
        Slot& s = slots[i];
        if (s.used.load(std::memory_order_relaxed)) continue;
        s.ranges = ranges.data();
        s.count = ranges.size();
        s.message = message_.c_str();
        s.message_size = message_.size();
        s.used.store(true, std::memory_order_release);
        if (i >= n) slots_in_use.store(i + 1, std::memory_order_release);
        slot_ = &s;
        return;
    }
}

StateFileGuard::~StateFileGuard() {
    if (slot_ == nullptr) return;
    const std::lock_guard lock(registration);
    static_cast<Slot*>(slot_)->used.store(false, std::memory_order_release);
}

}  // namespace fins::plc
#endif
