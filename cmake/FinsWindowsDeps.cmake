# The libraries of a Windows cross build (cmake/toolchains/x86_64-w64-mingw32.cmake), as the
# same target names the Linux build gets from find_package. Debian packages these for Linux
# only; the ones below are header-only (or have a header-only mode), so the host's headers
# serve a Windows build too. They are staged by symbolic links in one directory, so that
# the compiler sees them and not the rest of /usr/include (glibc's headers).
#
# Left out, and why (docs/windows.md): libmosquitto and protobuf are compiled libraries that
# Debian does not build for MinGW, so fins-bridge and its tests are not built for Windows;
# the Python module needs a Windows Python.
set(fins_win_include ${CMAKE_BINARY_DIR}/windows-deps/include)
file(MAKE_DIRECTORY ${fins_win_include})
foreach(dir boost fmt spdlog toml++ nlohmann CLI tl)
  if(NOT EXISTS /usr/include/${dir})
    message(FATAL_ERROR "/usr/include/${dir} not found: run scripts/deps.sh")
  endif()
  file(CREATE_LINK /usr/include/${dir} ${fins_win_include}/${dir} SYMBOLIC)
endforeach()

function(fins_win_header_target name)
  add_library(${name} INTERFACE IMPORTED GLOBAL)
  target_include_directories(${name} SYSTEM INTERFACE ${fins_win_include})
  if(ARGN)
    target_compile_definitions(${name} INTERFACE ${ARGN})
  endif()
endfunction()

find_package(Threads REQUIRED)
# localtime_r and gmtime_r: MinGW-w64's <time.h> has them (over localtime_s) when the
# POSIX thread-safe functions are asked for; the value is winpthreads' own.
add_compile_definitions(_POSIX_THREAD_SAFE_FUNCTIONS=200112L)
# Programs carry the C++ runtime and winpthreads (-static): fins.exe runs alone. libfins.dll
# uses MinGW-w64's runtime DLLs, which ship beside it (FinsWindowsPackage.cmake), so that
# a program and the DLL share one C++ runtime across libfins' C++ API.
string(APPEND CMAKE_EXE_LINKER_FLAGS " -static")
# fmt's header-only mode compiles its implementation into each user (FMT_HEADER_ONLY).
fins_win_header_target(fmt::fmt FMT_HEADER_ONLY)
# Debian's spdlog is configured for an external fmt (its tweakme.h); header-only mode.
fins_win_header_target(spdlog::spdlog SPDLOG_HEADER_ONLY SPDLOG_FMT_EXTERNAL FMT_HEADER_ONLY)
fins_win_header_target(tl::expected)
fins_win_header_target(CLI11::CLI11)
fins_win_header_target(nlohmann_json::nlohmann_json)
fins_win_header_target(tomlplusplus::tomlplusplus)
# Boost.Asio on Windows: Winsock 2 and its extensions (AcceptEx, ConnectEx), Windows 10 as
# the oldest target (_WIN32_WINNT 0x0A00).
fins_win_header_target(Boost::headers _WIN32_WINNT=0x0A00 WIN32_LEAN_AND_MEAN NOMINMAX)
target_link_libraries(Boost::headers INTERFACE ws2_32 mswsock)
