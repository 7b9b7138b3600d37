// CPU Unit errors: fatal / non-fatal error bits and codes for 06 01 (W342 5-3-17),
// FAL/FALS numbers and messages (5-3-23), ERROR CLEAR (5-3-27), the 20-record error
// log (5-3-28/5-3-29) and the end-code flag bits 6/7 (5-1-3).
// (Scaffolding: this class is being filled in by its issue-3 owner.)
#pragma once

#include <cstdint>

#include "plc/profile.hpp"
#include "plc/storage.hpp"

namespace fins::plc {

class ErrorState {
  public:
    ErrorState(const Profile& profile, Storage& storage);
    // Bits 7 (fatal) and 6 (non-fatal CPU error) to OR into every end code (W342 5-1-3).
    [[nodiscard]] std::uint16_t end_code_flags() const noexcept { return 0; }
};

}  // namespace fins::plc
