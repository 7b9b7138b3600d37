// The FINS write access log of W342 5-3-30/5-3-31.
// (Scaffolding: this class is being filled in by its issue-3 owner.)
#pragma once

#include "plc/profile.hpp"
#include "plc/storage.hpp"

namespace fins::plc {

class WriteAccessLog {
  public:
    WriteAccessLog(const Profile& profile, Storage& storage);
};

}  // namespace fins::plc
