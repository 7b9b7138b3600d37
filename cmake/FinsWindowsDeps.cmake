# The libraries of a Windows cross build (cmake/toolchains/x86_64-w64-mingw32.cmake), as the
# same target names the Linux build gets from find_package. Debian packages these for Linux
# only; the ones below are header-only (or have a header-only mode), so the host's headers
# serve a Windows build too (fmt and spdlog compiled here, below). They are staged by
# symbolic links in one directory, so that the compiler sees them and not the rest of
# /usr/include (glibc's headers).
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
# fmt and spdlog: compiled once each from Debian's headers (cmake/windows-deps/), as their
# Linux libraries are. Their header-only modes compiled the implementations into every
# file that includes them: about 6 s (fmt) and 3 s (spdlog) of MinGW -O3 per file, the
# larger part of this tree's build (docs/windows.md). libfins (FinsPackage.cmake) carries
# fmt's objects, so that its .dll and .a need nothing more.
add_library(fins_win_fmt STATIC ${CMAKE_CURRENT_LIST_DIR}/windows-deps/fmt.cpp)
target_include_directories(fins_win_fmt SYSTEM PUBLIC ${fins_win_include})
add_library(fmt::fmt ALIAS fins_win_fmt)
# Debian's spdlog is configured for an external fmt (its tweakme.h).
add_library(fins_win_spdlog STATIC ${CMAKE_CURRENT_LIST_DIR}/windows-deps/spdlog.cpp)
target_compile_definitions(fins_win_spdlog PUBLIC SPDLOG_COMPILED_LIB SPDLOG_FMT_EXTERNAL)
target_link_libraries(fins_win_spdlog PUBLIC fins_win_fmt)
add_library(spdlog::spdlog ALIAS fins_win_spdlog)
fins_win_header_target(tl::expected)
fins_win_header_target(CLI11::CLI11)
fins_win_header_target(nlohmann_json::nlohmann_json)
fins_win_header_target(tomlplusplus::tomlplusplus)
# Boost.Asio on Windows: Winsock 2 and its extensions (AcceptEx, ConnectEx), Windows 10 as
# the oldest target (_WIN32_WINNT 0x0A00).
fins_win_header_target(Boost::headers _WIN32_WINNT=0x0A00 WIN32_LEAN_AND_MEAN NOMINMAX)
target_link_libraries(Boost::headers INTERFACE ws2_32 mswsock)
