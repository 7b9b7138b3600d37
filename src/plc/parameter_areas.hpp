// Parameter areas of W342 5-3-7..5-3-9: PLC Setup (8010), I/O table (8012),
// routing tables (8013), CPU Bus Unit setup (8002) and the CV-mode whole range (8000).
// (Scaffolding: this class is being filled in by its issue-3 owner.)
#pragma once

#include "plc/profile.hpp"
#include "plc/storage.hpp"

namespace fins::plc {

class ParameterAreas {
  public:
    ParameterAreas(const Profile& profile, Storage& storage);
};

}  // namespace fins::plc
