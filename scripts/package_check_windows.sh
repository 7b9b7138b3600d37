#!/usr/bin/env bash
# Checks the Windows zip of `scripts/package.sh windows` on this Linux machine: its files,
# that fins.exe runs under wine, and that a user's CMake project (examples/) builds against
# the unpacked zip with MinGW-w64 through find_package(fins), with the DLL and static, and
# its program reads and writes the host's finsd. Usage: package_check_windows.sh ZIP
# HOST_BIN_DIR (a Linux finsd). Prints "windows package: N checks passed" last; exits
# non-zero on the first failure.
set -euo pipefail
zip=$1
host_bin=$2
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
finsd_pid=
export WINEPREFIX=${WINEPREFIX:-$root/build-windows/wineprefix} WINEDEBUG=-all
wine=/usr/lib/wine/wine64
cleanup() {
  [[ -n "$finsd_pid" ]] && finsd_stop
  rm -rf "$work"
}
trap cleanup EXIT
passed=0
check() { echo "  ok: $1"; passed=$((passed + 1)); }
fail() { echo "FAILED: $1" >&2; exit 1; }

unzip -q "$zip" -d "$work"
top=$(find "$work" -mindepth 1 -maxdepth 1 -type d -name 'finskit-*-windows-x86_64')
[[ -n "$top" ]] || fail "no finskit-VERSION-windows-x86_64/ in $zip"
for f in bin/fins.exe bin/finsd.exe bin/libfins.dll bin/libstdc++-6.dll bin/libgcc_s_seh-1.dll \
    bin/libwinpthread-1.dll lib/libfins.a lib/libfins.dll.a include/fins/client.hpp \
    include/tl/expected.hpp lib/cmake/fins/finsConfig.cmake lib/pkgconfig/fins.pc \
    README-windows.txt share/doc/finskit/docs/windows.md; do
  [[ -f "$top/$f" ]] || fail "the zip has no $f"
done
check "the zip holds the programs, the DLL, headers, CMake package and docs"
version=$("$wine" "$top/bin/fins.exe" --version | tr -d '\r')
[[ "$version" == "fins $(sed -n 's/^project(finskit VERSION \([0-9.]*\).*/\1/p' "$root/CMakeLists.txt")" ]] ||
  fail "fins.exe --version says '$version'"
check "fins.exe runs under wine: $version"
# finsd.exe from the zip starts once: "listening P", the page's assets inside it (GET /
# answers the page with no file beside the program), then it is ended.
source "$root/tests/scripts/round_trip_lib.sh"  # free_port, wait_for
exe_port=$(free_port)
http_port=$(free_port)
# (No control channel under wine: it has no AF_UNIX sockets, docs/windows.md.)
"$wine" "$top/bin/finsd.exe" --bind 127.0.0.1 --port "$exe_port" \
  --http "127.0.0.1:$http_port" >"$work/finsd-exe.log" 2>&1 &
exe_pid=$!
if ! wait_for 120 grep -q "^listening $exe_port" "$work/finsd-exe.log"; then
  kill -9 "$exe_pid" 2>/dev/null || true
  cat "$work/finsd-exe.log"; fail "finsd.exe from the zip did not listen"
fi
page=$(curl -sS --max-time 10 "http://127.0.0.1:$http_port/" || true)
kill "$exe_pid" 2>/dev/null || true
wait "$exe_pid" 2>/dev/null || true
grep -qi "<html" <<<"$page" || fail "finsd.exe from the zip did not serve its page"
check "finsd.exe runs under wine and serves the page from its own assets"

source "$root/scripts/finsd_start.sh"
finsd_start "$host_bin/finsd" --bind 127.0.0.1 --control "$work/ctl.sock"
for kind in shared static; do
  static=OFF; [[ $kind == static ]] && static=ON
  cmake -S "$root/examples" -B "$work/ex-$kind" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_TOOLCHAIN_FILE="$root/cmake/toolchains/x86_64-w64-mingw32.cmake" \
    -DCMAKE_PREFIX_PATH="$top" -DFINS_EXAMPLES_STATIC=$static >"$work/ex-$kind.log" 2>&1 ||
    { cat "$work/ex-$kind.log"; fail "examples ($kind) do not configure against the zip"; }
  ninja -C "$work/ex-$kind" >>"$work/ex-$kind.log" 2>&1 ||
    { tail -n 30 "$work/ex-$kind.log"; fail "examples ($kind) do not build against the zip"; }
  # The DLLs (libfins, MinGW-w64's runtime) are found beside the program, as Windows
  # looks for them.
  cp "$top"/bin/*.dll "$work/ex-$kind/"
  "$wine" "$work/ex-$kind/example_read_write.exe" 127.0.0.1 "$finsd_port" >"$work/run-$kind.log" 2>&1 ||
    { cat "$work/run-$kind.log"; fail "example_read_write.exe ($kind) failed against finsd"; }
  check "a CMake project links libfins ($kind) from the zip and talks to finsd"
done
echo "windows package: $passed checks passed"
