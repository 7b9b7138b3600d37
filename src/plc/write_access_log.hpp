// The FINS write access log of W342 5-3-30/5-3-31.
// (Scaffolding: this class is being filled in by its issue-3 owner.)
#pragma once

#include <chrono>

#include "fins/error.hpp"
#include "fins/frame.hpp"
#include "plc/profile.hpp"
#include "plc/storage.hpp"

namespace fins::plc {

class WriteAccessLog {
  public:
    WriteAccessLog(const Profile& profile, Storage& storage);
    // Called by the dispatcher after every FINS write command (the commands marked
    // "Disabled" under network write protection in W342 5-1-2) with its end code.
    // (Scaffolding: no-op until implemented.)
    void record(const NodeAddress&, CommandCode, EndCode,
                std::chrono::system_clock::time_point) noexcept {}
};

}  // namespace fins::plc
