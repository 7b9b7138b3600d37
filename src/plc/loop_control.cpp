#include "plc/loop_control.hpp"

namespace fins::plc {

LoopControl::LoopControl(const Profile&, Storage&) {}

}  // namespace fins::plc
