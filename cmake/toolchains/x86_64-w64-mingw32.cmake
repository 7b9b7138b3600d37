# Windows x86-64 from an x86-64 Debian host (docs/windows.md): Debian's MinGW-w64 cross
# compiler, the posix thread model (g++-mingw-w64-x86-64-posix: std::thread and
# std::mutex through winpthreads). Only header-only libraries are used from the host's
# /usr/include, through a staged directory (cmake/FinsWindowsDeps.cmake): putting
# /usr/include itself on the path would mix glibc's headers into a Windows build.
# Tests run under Debian's wine (CMAKE_CROSSCOMPILING_EMULATOR).
set(CMAKE_SYSTEM_NAME Windows)
set(CMAKE_SYSTEM_PROCESSOR x86_64)
set(CMAKE_C_COMPILER x86_64-w64-mingw32-gcc-posix)
set(CMAKE_CXX_COMPILER x86_64-w64-mingw32-g++-posix)
set(CMAKE_RC_COMPILER x86_64-w64-mingw32-windres)
set(CMAKE_FIND_ROOT_PATH /usr/x86_64-w64-mingw32)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
# Packages also where CMAKE_PREFIX_PATH says (an unpacked finskit zip), not only under
# the MinGW root: the Windows tree itself looks for no CMake package but Threads.
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)
# Debian 12's wine64 package has no wine on PATH (that is the "wine" package).
set(CMAKE_CROSSCOMPILING_EMULATOR /usr/lib/wine/wine64)
