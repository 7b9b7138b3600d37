# shellcheck shell=bash disable=SC2034
# Sourced by scripts/build.sh and scripts/package.sh: ccache (optional, not a dependency)
# makes rebuilds in several work trees cheap. Sets fins_ccache_args to the CMake options
# that use it (empty without ccache).
#
# Every target with a precompiled header (the test binaries' GoogleTest, see
# tests/CMakeLists.txt) is compiled with `-include cmake_pch.hxx`: ccache caches those
# compiles, and the .gch itself, only with the sloppiness pch_defines,time_macros; without
# it each such compile is "could not use precompiled header", run every time. No source
# uses __DATE__/__TIME__, so time_macros loses nothing. Added to whatever the user's
# ccache configuration already says.
fins_ccache_args=()
if command -v ccache >/dev/null; then
  fins_ccache_sloppiness=${CCACHE_SLOPPINESS:-$(ccache -k sloppiness 2>/dev/null || true)}
  export CCACHE_SLOPPINESS="${fins_ccache_sloppiness:+$fins_ccache_sloppiness,}pch_defines,time_macros"
  fins_ccache_args=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
