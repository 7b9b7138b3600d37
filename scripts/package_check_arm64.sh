#!/usr/bin/env bash
# Checks the arm64 .debs of `scripts/package.sh arm64` on this (x86-64) machine, where
# they cannot be installed: each is for arm64, its dependencies name the arm64 libraries'
# packages, and the programs unpacked from finskit run under qemu-aarch64 (`--version`,
# and finsd answers the unpacked fins on 127.0.0.1). Usage: package_check_arm64.sh DEB...
# Prints "arm64 packages: N checks passed" last; exits non-zero on the first failure.
set -euo pipefail
work=$(mktemp -d)
finsd_pid=
cleanup() {
  [[ -n "$finsd_pid" ]] && { kill "$finsd_pid" 2>/dev/null || true; wait "$finsd_pid" 2>/dev/null || true; }
  rm -rf "$work"
}
trap cleanup EXIT
passed=0
check() { echo "  ok: $1"; passed=$((passed + 1)); }
fail() { echo "FAILED: $1" >&2; exit 1; }
emu=(qemu-aarch64 -L /)
declare -A seen
for deb in "$@"; do
  name=$(dpkg-deb -f "$deb" Package)
  arch=$(dpkg-deb -f "$deb" Architecture)
  [[ "$arch" == arm64 ]] || fail "$name is for $arch"
  check "$name is for arm64"
  seen[$name]=$deb
done
for name in finskit libfins0.1 libfins-dev; do
  [[ -n "${seen[$name]:-}" ]] || fail "no $name package"
done
depends=$(dpkg-deb -f "${seen[finskit]}" Depends)
for lib in libmosquitto1 libprotobuf32 libfmt9 libc6 libstdc++6; do
  grep -q "$lib" <<<"$depends" || fail "finskit does not depend on $lib: $depends"
done
check "finskit depends on its arm64 libraries ($depends)"
dpkg-deb -x "${seen[finskit]}" "$work/root"
dpkg-deb -x "${seen[libfins0.1]}" "$work/root"
for program in finsd fins fins-bridge; do
  file "$work/root/usr/bin/$program" | grep -q "ARM aarch64" || fail "$program is not arm64"
  "${emu[@]}" "$work/root/usr/bin/$program" --version | grep -q "[0-9]\.[0-9]" ||
    fail "$program --version"
  check "$program runs under qemu-aarch64"
done
ls "$work"/root/usr/lib/aarch64-linux-gnu/libfins.so.* >/dev/null 2>&1 ||
  fail "libfins.so is not in /usr/lib/aarch64-linux-gnu"
check "libfins.so in the arm64 multiarch directory"
for page in usr/share/man/man1/fins.1.gz usr/share/man/man8/finsd.8.gz \
    usr/share/man/man8/fins-bridge.8.gz; do
  zcat "$work/root/$page" | grep -q "^\.SH" || fail "$page is empty"
done
check "man pages made by the arm64 programs"
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(socket.AF_INET, socket.SOCK_DGRAM); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
XDG_RUNTIME_DIR=$work "${emu[@]}" "$work/root/usr/bin/finsd" --bind 127.0.0.1 --port "$port" --no-tcp \
  >"$work/finsd.log" 2>&1 &
finsd_pid=$!
for _ in $(seq 1 300); do grep -q "listening $port" "$work/finsd.log" && break; sleep 0.1; done
grep -q "listening $port" "$work/finsd.log" || fail "the packaged finsd did not listen"
"${emu[@]}" "$work/root/usr/bin/fins" --port "$port" write D7 77 >/dev/null
[[ "$("${emu[@]}" "$work/root/usr/bin/fins" --port "$port" read D7 --json)" == *'"values":[77]'* ]] ||
  fail "the packaged fins did not read back D7"
check "the packaged finsd answers the packaged fins"
echo "arm64 packages: $passed checks passed"
