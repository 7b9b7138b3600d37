#include "plc/scan_cycle.hpp"

namespace fins::plc {

ScanCycle::ScanCycle(const Profile&, Storage&) {}

}  // namespace fins::plc
