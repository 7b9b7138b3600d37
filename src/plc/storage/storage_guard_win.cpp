// StateFileGuard on Windows (contract in storage_guard.hpp): nothing to guard. The guard
// exists on Linux because a MAP_SHARED file truncated from outside raises SIGBUS at the
// next access. On Windows that cannot happen: finsd opens the state file without
// FILE_SHARE_WRITE (storage_os_win.cpp), so no other process can open it to write or
// truncate it, and Windows refuses to shrink a file below a mapped view
// (ERROR_USER_MAPPED_FILE) in any case. Storage::intact() stays true there.
#ifdef _WIN32
#include "plc/storage/storage_guard.hpp"

namespace fins::plc {

std::string state_file_lost_message(const std::string& path) {
    return "finsd: state file " + path + " shrank while finsd ran\n";
}

StateFileGuard::StateFileGuard(std::span<const std::pair<void*, std::size_t>>,
                               const std::string& path)
    : message_(state_file_lost_message(path)) {}

StateFileGuard::~StateFileGuard() = default;

}  // namespace fins::plc
#endif
