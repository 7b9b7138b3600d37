#!/usr/bin/env bash
# Configures and builds one tree. Usage:
#   scripts/build.sh [release|asan|tsan|fuzz|arm64|windows] [TARGET...]
# (no targets: everything the tree builds; for fuzz, every fuzzer: fuzz/CMakeLists.txt's
# fuzz_all; for tsan, the binaries of the multi-threaded tests and what they run:
# tests/CMakeLists.txt's fins_tsan_all; for arm64 and windows, the programs and the unit
# tests it runs: tests/CMakeLists.txt's fins_cross_all). FINS_BUILD_DIR puts the tree
# elsewhere; FINS_NINJA_ARGS are extra ninja options (-n: print what would be built, build
# nothing).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
kind=${1:-release}
shift || true
jobs=${FINS_JOBS:-$(nproc)}
# The clang trees link with lld: an ASan+UBSan finsd (150 MB) links in 2.2 s against
# 11.9 s with GNU ld, and the ASan tree links 55 programs (docs/testing.md).
lld=(-DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld -DCMAKE_SHARED_LINKER_FLAGS=-fuse-ld=lld
  -DCMAKE_MODULE_LINKER_FLAGS=-fuse-ld=lld)
source "$root/scripts/release_opt.sh"
case "$kind" in
  # What users run: optimised, and not failing on a newer compiler's new warning.
  release) dir=build; args=(-DCMAKE_BUILD_TYPE=Release "${fins_release_opt[@]}") ;;
  # What CI tests: ASan+UBSan, warnings as errors, everything (benchmarks compile too),
  # and the libFuzzer targets on the same libraries (their coverage instrumentation too):
  # one tree instead of two. clang-14 compiles it in about half the time g++ takes with
  # the sanitizers; line tables are what a sanitizer's stack trace shows (docs/testing.md).
  asan) dir=build-asan; args=(-DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O0 -gline-tables-only"
    -DCMAKE_CXX_COMPILER=clang++-14 "${lld[@]}" -DFINS_SANITIZE=ON -DFINS_FUZZ=ON -DFINS_WERROR=ON) ;;
  # ThreadSanitizer: only the tests in which our code runs on more than one thread
  # (tests/CMakeLists.txt's fins_tsan_filters), and the Python module for VirtualPlc's.
  # clang-14 and line tables, as the ASan tree.
  tsan) dir=build-tsan; args=(-DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O0 -gline-tables-only"
    -DCMAKE_CXX_COMPILER=clang++-14 "${lld[@]}" -DFINS_SANITIZE=thread -DFINS_WERROR=ON
    -DFINS_BENCH=OFF -DFINS_EXAMPLES=OFF -DFINS_PYTHON=ON -DPython3_EXECUTABLE=/usr/bin/python3) ;;
  # The fuzzers alone, optimised, for long runs by hand (CI runs the ASan tree's). Line
  # tables only (-gline-tables-only) are what a fuzzer's stack trace needs; full -g
  # made the clang -O2 compiles about a quarter slower.
  fuzz) dir=build-fuzz; args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG" -DFINS_FUZZ=ON -DFINS_TESTS=OFF -DFINS_BENCH=OFF -DFINS_EXAMPLES=OFF -DCMAKE_CXX_COMPILER=clang++-14 "${lld[@]}") ;;
  # Linux arm64 (docs/platforms.md): Debian's cross compiler and :arm64 libraries, tests
  # under qemu-user; optimised as users get it, our warnings as errors (char is unsigned
  # there) but for the middle-end ones GCC 12 raises falsely on std::string at -O3
  # (-Wrestrict, -Warray-bounds, -Wstringop-overflow: GCC PR 105329, 105651), which the
  # ASan tree (-O0) never sees; they still print.
  arm64) dir=build-arm64
    "$root/scripts/deps.sh" arm64
    args=(-DCMAKE_TOOLCHAIN_FILE="$root/cmake/toolchains/aarch64-linux-gnu.cmake"
      -DCMAKE_BUILD_TYPE=Release "${fins_release_opt[@]}" -DFINS_WERROR=ON
      "-DCMAKE_CXX_FLAGS=-Wno-error=restrict -Wno-error=array-bounds -Wno-error=stringop-overflow"
      -DFINS_BENCH=OFF -DFINS_EXAMPLES=OFF
      -DCMAKE_INSTALL_PREFIX=/usr -DFINS_MAN=ON
      # GNUInstallDirs picks Debian's multiarch libdir only when not cross compiling.
      -DCMAKE_INSTALL_LIBDIR=lib/aarch64-linux-gnu) ;;
  # Windows x86-64 (docs/windows.md): Debian's MinGW-w64 g++ (posix threads), the
  # header-only libraries staged by cmake/FinsWindowsDeps.cmake, tests under wine.
  windows) dir=build-windows
    "$root/scripts/deps.sh" windows
    args=(-DCMAKE_TOOLCHAIN_FILE="$root/cmake/toolchains/x86_64-w64-mingw32.cmake"
      -DCMAKE_BUILD_TYPE=Release "${fins_release_opt[@]}" -DFINS_WERROR=ON
      "-DCMAKE_CXX_FLAGS=-Wno-error=restrict -Wno-error=array-bounds -Wno-error=stringop-overflow"
      -DFINS_BENCH=OFF -DFINS_EXAMPLES=OFF -DFINS_DOCS=OFF) ;;
  *) echo "usage: $0 [release|asan|tsan|fuzz|arm64|windows]" >&2; exit 2 ;;
esac
# The finskit Python module (release tree) is for Debian's interpreter, whatever python3
# comes first on PATH (a pyenv one may lack the headers, or be another version).
if [[ "$kind" == release && -x /usr/bin/python3 ]]; then
  args+=(-DPython3_EXECUTABLE=/usr/bin/python3)
fi
source "$root/scripts/ccache.sh"
args+=("${fins_ccache_args[@]}")
dir=${FINS_BUILD_DIR:-$root/$dir}
cmake -S "$root" -B "$dir" -G Ninja "${args[@]}" >/dev/null
# The fuzz tree's "everything" would also build the libraries' other programs: its
# default is the fuzzers alone, which CMake lists (fuzz_all).
if [[ "$kind" == fuzz && $# -eq 0 ]]; then set -- fuzz_all; fi
if [[ "$kind" == tsan && $# -eq 0 ]]; then set -- fins_tsan_all; fi
if [[ ( "$kind" == arm64 || "$kind" == windows ) && $# -eq 0 ]]; then set -- fins_cross_all; fi
read -r -a ninja_args <<<"${FINS_NINJA_ARGS:-}"
ninja -C "$dir" -j "$jobs" "${ninja_args[@]}" "$@"
