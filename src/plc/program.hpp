// The UM (user program) area of W342 5-3-10..5-3-12: its bytes, size per profile,
// protection.
// (Scaffolding: this class is being filled in by its issue-3 owner.)
#pragma once

#include "plc/profile.hpp"
#include "plc/storage.hpp"

namespace fins::plc {

class UserProgram {
  public:
    UserProgram(const Profile& profile, Storage& storage);
};

}  // namespace fins::plc
