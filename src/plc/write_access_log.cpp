#include "plc/write_access_log.hpp"

namespace fins::plc {

WriteAccessLog::WriteAccessLog(const Profile&, Storage&) {}

}  // namespace fins::plc
