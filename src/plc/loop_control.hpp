// Loop Control Board function blocks read by 02 40 (seed 001).
// (Scaffolding: this class is being filled in by its issue-3 owner.)
#pragma once

#include "plc/profile.hpp"
#include "plc/storage.hpp"

namespace fins::plc {

class LoopControl {
  public:
    LoopControl(const Profile& profile, Storage& storage);
};

}  // namespace fins::plc
