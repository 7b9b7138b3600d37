#include "plc/errors.hpp"

namespace fins::plc {

ErrorState::ErrorState(const Profile&, Storage&) {}

}  // namespace fins::plc
