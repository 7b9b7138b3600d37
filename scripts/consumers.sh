#!/usr/bin/env bash
# Builds the examples/ as a separate project against libfins installed in a temporary
# prefix, the three ways a user would: CMake find_package (shared and static) and
# pkg-config, then runs each against the installed finsd.
# Usage: scripts/consumers.sh [BUILD_DIR]   (default build-pkg, see scripts/package.sh)
# Prints "consumers: N checks passed" last; exits non-zero on the first failure.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build-pkg}
jobs=${FINS_JOBS:-$(nproc)}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix="$work/prefix"
source "$root/scripts/finsd_start.sh"
passed=0

cmake --install "$build" --prefix "$prefix" >/dev/null
libdir=$(dirname "$(find "$prefix" -name fins.pc -print -quit)")/..
examples=(read_write pipelined_reads typed_command error_handling)

echo "== consumer: CMake find_package(fins), shared and static"
for kind in shared static; do
  static=OFF; [[ $kind == static ]] && static=ON
  cmake -S "$root/examples" -B "$work/cmake-$kind" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$prefix" -DFINS_EXAMPLES_STATIC=$static >/dev/null
  ninja -C "$work/cmake-$kind" -j "$jobs" >/dev/null
done
# The shared build really uses the installed libfins.so with its SONAME, the static one
# does not load it at all.
ldd "$work/cmake-shared/example_read_write" | grep "libfins.so.* => $prefix" >/dev/null
passed=$((passed + 1))
no_libfins_so() {
  if ldd "$1" | grep libfins.so; then echo "FAILED: $1 links libfins.so" >&2; exit 1; fi
}
no_libfins_so "$work/cmake-static/example_read_write"
passed=$((passed + 1))

echo "== consumer: pkg-config fins"
mkdir -p "$work/pc"
export PKG_CONFIG_PATH="$libdir/pkgconfig"
for ex in "${examples[@]}"; do
  # shellcheck disable=SC2046
  g++ $(pkg-config --cflags fins) "$root/examples/$ex.cpp" -o "$work/pc/$ex" \
    $(pkg-config --libs fins) -Wl,-rpath,"$(pkg-config --variable=libdir fins)"
done
# libfins.a as README says: fins-static names the archive and what it needs (fmt, threads).
# shellcheck disable=SC2046
g++ $(pkg-config --cflags fins-static) "$root/examples/read_write.cpp" \
  -o "$work/pc/read_write_static" $(pkg-config --libs fins-static)
no_libfins_so "$work/pc/read_write_static"
passed=$((passed + 1))

echo "== consumers against the installed finsd"
finsd_start "$prefix/bin/finsd" --bind 127.0.0.1
for ex in "${examples[@]}"; do
  for dir in cmake-shared cmake-static; do
    "$work/$dir/example_$ex" 127.0.0.1 "$finsd_port" >/dev/null
    passed=$((passed + 1))
  done
  "$work/pc/$ex" 127.0.0.1 "$finsd_port" >/dev/null
  passed=$((passed + 1))
done
"$work/pc/read_write_static" 127.0.0.1 "$finsd_port" --tcp >/dev/null
passed=$((passed + 1))
# The installed fins CLI reads what the examples wrote.
"$prefix/bin/fins" --port "$finsd_port" read D100 3 | grep "D102 *3" >/dev/null
passed=$((passed + 1))
finsd_stop
echo "consumers: $passed checks passed"
