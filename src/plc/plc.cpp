#include "plc/plc.hpp"

#include <utility>

namespace fins::plc {

Plc::Plc(Profile profile, std::unique_ptr<Storage> storage)
    : storage_(storage ? std::move(storage) : std::make_unique<Storage>()),
      memory_(std::move(profile)),
      parameters_(memory_.profile(), *storage_),
      program_(memory_.profile(), *storage_),
      loop_control_(memory_.profile(), *storage_),
      clock_(memory_.profile(), *storage_),
      scan_cycle_(memory_.profile(), *storage_),
      errors_(memory_.profile(), *storage_),
      messages_(memory_.profile(), *storage_),
      write_access_log_(memory_.profile(), *storage_) {}

}  // namespace fins::plc
