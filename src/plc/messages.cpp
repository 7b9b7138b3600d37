#include "plc/messages.hpp"

namespace fins::plc {

Messages::Messages(const Profile&, Storage&) {}

}  // namespace fins::plc
