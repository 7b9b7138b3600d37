#!/usr/bin/env bash
# Configures and builds one tree. Usage: scripts/build.sh [release|asan|fuzz] [TARGET...]
# (no targets: everything the tree builds; for fuzz, every fuzzer: fuzz/CMakeLists.txt's
# fuzz_all). FINS_BUILD_DIR puts the tree elsewhere; FINS_NINJA_ARGS are extra ninja
# options (-n: print what would be built, build nothing).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
kind=${1:-release}
shift || true
jobs=${FINS_JOBS:-$(nproc)}
case "$kind" in
  # What users run: optimised, and not failing on a newer compiler's new warning.
  release) dir=build; args=(-DCMAKE_BUILD_TYPE=Release) ;;
  # What CI tests: ASan+UBSan, warnings as errors, everything (benchmarks compile too).
  asan) dir=build-asan; args=(-DCMAKE_BUILD_TYPE=Debug -DFINS_SANITIZE=ON -DFINS_WERROR=ON) ;;
  fuzz) dir=build-fuzz; args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DFINS_FUZZ=ON -DFINS_TESTS=OFF -DCMAKE_CXX_COMPILER=clang++-14) ;;
  *) echo "usage: $0 [release|asan|fuzz]" >&2; exit 2 ;;
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
read -r -a ninja_args <<<"${FINS_NINJA_ARGS:-}"
ninja -C "$dir" -j "$jobs" "${ninja_args[@]}" "$@"
