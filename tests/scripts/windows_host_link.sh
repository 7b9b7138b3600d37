#!/usr/bin/env bash
# finsd.exe and fins.exe under wine on COM ports that Wine maps onto pty pairs (socat),
# talking Host Link to the host's Linux fins and finsd (docs/windows.md, docs/serial.md):
# - Host Link: finsd.exe --serial cpu=COM5 (9600 7E2, the defaults); the Linux fins on the
#   pty's other end writes and reads D100, and FINS/UDP sees the same word;
# - the Serial Gateway: finsd.exe --serial scu1.1=COM6,network=5 relays FINS/UDP requests
#   for network 5 as Host Link FINS to a Linux finsd on the other end (--serial cpu=...);
#   a write through the gateway is read back from the Linux finsd over its own FINS/UDP;
# - the client: fins.exe --serial COM10 (two digits: opened as \\.\COM10) reads and
#   writes D200 of the same Linux finsd (its scu1.2 port in Host Link mode); a COM port
#   that is not mapped is "cannot open" with exit 3;
# - a line that goes away (socat ended): the gateway answers 0205 (fins exit 4), the
#   Host Link port logs "lost" and retries, and finsd.exe keeps answering FINS/UDP.
# Each COM port is a symlink $WINEPREFIX/dosdevices/comN -> /dev/pts/M (removed on exit).
# Usage: windows_host_link.sh WINDOWS_BIN_DIR HOST_BIN_DIR (WINEPREFIX and WINEDEBUG from
# ctest's environment). Every wait is for a condition, bounded in time; every process
# started is ended on exit (only those: wineserver is left to wine).
set -euo pipefail
bin=$1
host_bin=$2
wine=/usr/lib/wine/wine64
: "${WINEPREFIX:?windows host link: WINEPREFIX is not set}"
for tool in "$host_bin/fins" "$host_bin/finsd"; do
  [[ -x "$tool" ]] || { echo "windows host link: no $tool" >&2; exit 1; }
done
[[ -f "$bin/finsd.exe" && -f "$bin/fins.exe" ]] ||
  { echo "windows host link: no finsd.exe/fins.exe in $bin" >&2; exit 1; }
command -v socat >/dev/null || { echo "windows host link: socat is missing" >&2; exit 1; }
[[ -d "$WINEPREFIX/dosdevices" ]] ||
  { echo "windows host link: no $WINEPREFIX/dosdevices (windows_wine_prefix makes it)" >&2; exit 1; }
source "$(dirname "$0")/round_trip_lib.sh"  # free_port, wait_for, round_trip_workdir
round_trip_workdir
links=()
trap 'rm -f "${links[@]}"; round_trip_cleanup' EXIT
fail() {
  echo "windows host link: $*" >&2
  tail -n 20 "$work"/*.log >&2 || true
  exit 1
}
passed=0
check() { if "$@"; then passed=$((passed + 1)); else fail "failed: $*"; fi; }

# pty_pair NAME: a socat pty pair, its two devices in $pty_a and $pty_b, socat's PID in
# $pty_pid.
pty_pair() {
  socat -d -d pty,raw,echo=0 pty,raw,echo=0 2>"$work/$1.socat.log" &
  pty_pid=$!
  pids+=("$pty_pid")
  wait_for 10 grep -q "starting data transfer loop" "$work/$1.socat.log" ||
    fail "socat made no pty pair ($1)"
  local ptys
  mapfile -t ptys < <(grep -o 'PTY is /dev/.*' "$work/$1.socat.log" | cut -c8-)
  ((${#ptys[@]} == 2)) || fail "socat named ${#ptys[@]} ptys ($1)"
  pty_a=${ptys[0]}
  pty_b=${ptys[1]}
}
# map_com N DEVICE: COMN in the prefix is DEVICE (what a user does with a real port too).
map_com() {
  local link="$WINEPREFIX/dosdevices/com$1"
  ln -sfn "$2" "$link"
  links+=("$link")
}
json_values() { grep -o '"values":\[[^]]*\]'; }

pty_pair cpu  # finsd.exe's Host Link port <-> the Linux fins
cpu_a=$pty_a cpu_b=$pty_b cpu_socat=$pty_pid
pty_pair gateway  # finsd.exe's Serial Gateway port <-> the Linux finsd's cpu port
gateway_a=$pty_a gateway_b=$pty_b gateway_socat=$pty_pid
pty_pair client  # fins.exe <-> the Linux finsd's scu1.2 port (Host Link)
client_a=$pty_a client_b=$pty_b
map_com 5 "$cpu_a"
map_com 6 "$gateway_a"
map_com 10 "$client_a"

# The Linux finsd behind the gateway, and at the end of fins.exe's line.
linux_port=$(free_port)
"$host_bin/finsd" --bind 127.0.0.1 --port "$linux_port" --control "$work/ctl.sock" \
  --serial "cpu=$gateway_b" --serial "scu1.2=$client_b,mode=hostlink" >"$work/linux-finsd.log" 2>&1 &
pids+=($!)
wait_for 60 grep -q "^listening $linux_port" "$work/linux-finsd.log" || fail "the Linux finsd did not listen"

port=$(free_port)
"$wine" "$bin/finsd.exe" --bind 127.0.0.1 --port "$port" \
  --serial cpu=COM5 --serial scu1.1=COM6,network=5 >"$work/finsd-exe.log" 2>&1 &
pids+=($!)
wait_for 120 grep -q "^listening $port" "$work/finsd-exe.log" || fail "finsd.exe did not listen"
check grep -q "serial cpu on COM5 9600 7E2, Host Link unit 0" "$work/finsd-exe.log"
check grep -q "serial gateway port scu1.1 on COM6" "$work/finsd-exe.log"

# Host Link: the Linux fins on the other end of COM5.
hl() { timeout 60 "$host_bin/fins" --serial "$cpu_b" "$@"; }
check hl write D100 4242 >/dev/null
check test "$(hl read D100 --json | json_values)" = '"values":[4242]'
check hl write D101 -7 --as int16 >/dev/null
check test "$(hl read D100 2 --as int16 --json | json_values)" = '"values":[4242,-7]'
# The same memory over FINS/UDP: the serial port is one more way into the same PLC.
check test "$(timeout 60 "$host_bin/fins" --port "$port" read D100 2 --as int16 --json | json_values)" \
  = '"values":[4242,-7]'

# The Serial Gateway: FINS/UDP to finsd.exe, network 5, Host Link unit 0 (DA1 1), on COM6.
gw() { timeout 60 "$host_bin/fins" --port "$port" --dest 5.1.0 "$@"; }
check timeout 60 "$host_bin/fins" --port "$linux_port" write D100 777 >/dev/null
check test "$(gw read D100 --json | json_values)" = '"values":[777]'
check gw write D101 55 >/dev/null
check test "$(timeout 60 "$host_bin/fins" --port "$linux_port" read D100 2 --json | json_values)" \
  = '"values":[777,55]'

# The client: fins.exe on COM10, Host Link to the Linux finsd's scu1.2 port.
win_fins() { timeout 60 "$wine" "$bin/fins.exe" --serial COM10 "$@" | tr -d '\r'; }
check win_fins write D200 31337 >/dev/null
check test "$(win_fins read D200 --json | json_values)" = '"values":[31337]'
check test "$(timeout 60 "$host_bin/fins" --port "$linux_port" read D200 --json | json_values)" \
  = '"values":[31337]'
set +e
missing=$(timeout 60 "$wine" "$bin/fins.exe" --serial COM9 read D200 2>&1 | tr -d '\r')
rc=${PIPESTATUS[0]}
set -e
check test "$rc" -eq 3
check grep -q "cannot open the serial line: COM9" <<<"$missing"

# Lines that go away: socat ended, its ptys gone under finsd.exe's open COM ports.
kill "$gateway_socat"
wait "$gateway_socat" 2>/dev/null || true
set +e
gone=$(gw read D100 2>&1)
rc=$?
set -e
check test "$rc" -eq 4
check grep -q "0x0205" <<<"$gone"
kill "$cpu_socat"
wait "$cpu_socat" 2>/dev/null || true
check wait_for 30 grep -q "serial cpu (COM5): lost" "$work/finsd-exe.log"
check test "$(timeout 60 "$host_bin/fins" --port "$port" read D100 --json | json_values)" \
  = '"values":[4242]'
echo "windows host link: $passed checks passed"
