// The CPU Unit clock of W342 5-3-19/5-3-20: host time plus a retained offset.
// (Scaffolding: this class is being filled in by its issue-3 owner.)
#pragma once

#include "plc/profile.hpp"
#include "plc/storage.hpp"

namespace fins::plc {

class Clock {
  public:
    Clock(const Profile& profile, Storage& storage);
};

}  // namespace fins::plc
