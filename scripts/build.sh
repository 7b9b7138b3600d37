#!/usr/bin/env bash
# Configures and builds one tree. Usage: scripts/build.sh [release|asan|fuzz] [TARGET...]
# (no targets: everything the tree builds)
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
# ccache (optional, not a dependency) makes rebuilds in several work trees cheap.
if command -v ccache >/dev/null; then args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S "$root" -B "$root/$dir" -G Ninja "${args[@]}" >/dev/null
if [[ "$kind" == fuzz ]]; then
  ninja -C "$root/$dir" -j "$jobs" fuzz_frame fuzz_tcp fuzz_address fuzz_dispatch fuzz_session fuzz_files fuzz_host_link fuzz_router fuzz_serial_gateway fuzz_serial_session fuzz_http fuzz_scenario_expr
else
  ninja -C "$root/$dir" -j "$jobs" "$@"
fi
