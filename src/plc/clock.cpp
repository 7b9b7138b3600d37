#include "plc/clock.hpp"

namespace fins::plc {

Clock::Clock(const Profile&, Storage&) {}

}  // namespace fins::plc
