// MSG messages 0-7 for MESSAGE READ / MESSAGE CLEAR (W342 5-3-21, 5-3-22).
// (Scaffolding: this class is being filled in by its issue-3 owner.)
#pragma once

#include "plc/profile.hpp"
#include "plc/storage.hpp"

namespace fins::plc {

class Messages {
  public:
    Messages(const Profile& profile, Storage& storage);
};

}  // namespace fins::plc
