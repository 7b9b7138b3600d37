#include "plc/program.hpp"

namespace fins::plc {

UserProgram::UserProgram(const Profile&, Storage&) {}

}  // namespace fins::plc
