// What happens when a state file shrinks under a running finsd (issue 18 item 5).
//
// The retained sections are the state file itself, mapped MAP_SHARED (storage.hpp). An
// operator's `: > finsd.state` (or any truncation) takes the pages past the new end out
// of the file; the next load or store there raises SIGBUS, and Linux gives no other
// notice (an fstat before each access would race the truncation anyway, and an fcntl
// lease needs CAP_LEASE or the file's owner, is refused on many file systems, and blocks
// the operator's open for lease-break-time).
//
// So the guard takes the SIGBUS: when the faulting address lies in a guarded state
// file's mapping, it writes one line naming the file to stderr and ends the process
// with `state_file_lost_exit_code` (_exit: only async-signal-safe calls; no destructor
// runs and nothing more is written to any state file, exactly as after a SIGKILL, which
// the design already survives: other state files keep every acknowledged write). The
// emptied file is refused at the next start (exit 3) until --reset-state moves it aside.
// A SIGBUS anywhere else goes on to the previous handler (or kills as before): the
// guard never hides another fault. No sigsetjmp: the access is never resumed.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <utility>

namespace fins::plc {

// finsd's exit code when a state file shrank under it (docs/finsd.md, "finsd").
inline constexpr int state_file_lost_exit_code = 4;

// The exact line the guard writes (tests compare with it).
std::string state_file_lost_message(const std::string& path);

// One state file's mappings, guarded while the object lives. `ranges` must stay
// unchanged and alive until the guard is destroyed. Installs the SIGBUS handler the
// first time. At most `capacity` files at once; beyond that a file is unguarded (a
// SIGBUS there kills as it did before).
class StateFileGuard {
  public:
    static constexpr std::size_t capacity = 16384;

    StateFileGuard(std::span<const std::pair<void*, std::size_t>> ranges, const std::string& path);
    ~StateFileGuard();
    StateFileGuard(const StateFileGuard&) = delete;
    StateFileGuard& operator=(const StateFileGuard&) = delete;

    [[nodiscard]] bool guarded() const noexcept { return slot_ != nullptr; }

  private:
    void* slot_ = nullptr;
    std::string message_;
};

}  // namespace fins::plc
