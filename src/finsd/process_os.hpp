// finsd's process-wide settings that differ by OS (docs/windows.md, "finsd.exe").
#pragma once

#include <csignal>

namespace fins::finsd {

// A file size limit (RLIMIT_FSIZE) then fails the state file's reservation with EFBIG, a
// clear exit 3, instead of killing finsd with SIGXFSZ. Windows has neither the limit nor
// the signal: nothing to do there.
inline void ignore_file_size_signal() {
#ifndef _WIN32
    std::signal(SIGXFSZ, SIG_IGN);
#endif
}

}  // namespace fins::finsd
