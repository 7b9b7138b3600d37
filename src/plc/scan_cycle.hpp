// The simulated scan cycle: cycle-time statistics for 06 20 (W342 5-3-18), and
// the time base of the clock pulses and condition flags.
// (Scaffolding: this class is being filled in by its issue-3 owner.)
#pragma once

#include <chrono>

#include "plc/profile.hpp"
#include "plc/storage.hpp"

namespace fins::plc {

class ScanCycle {
  public:
    ScanCycle(const Profile& profile, Storage& storage);
    // Brings the simulated cycle up to `now`; the dispatcher calls it before every
    // request. (Scaffolding: no-op until implemented.)
    void advance(std::chrono::system_clock::time_point) noexcept {}
};

}  // namespace fins::plc
