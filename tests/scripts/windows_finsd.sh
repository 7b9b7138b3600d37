#!/usr/bin/env bash
# finsd.exe under wine answering the host's Linux fins on 127.0.0.1 (docs/windows.md):
# "listening P" as finsd prints it; D100 written and read over FINS/UDP and FINS/TCP;
# the control channel (issue 28: loopback TCP, the channel file `<port> <token>`):
# `finsd.exe ctl status` answers the status JSON, `finsd.exe ctl mode program` is seen by
# the Linux fins over FINS/UDP, a connection without the token (or with a wrong one) is
# closed without an answer, a second finsd.exe on a live channel file is refused (exit 3),
# and ctl against a missing file says "cannot connect" (exit 3);
# retained memory: a write acknowledged, finsd.exe killed (SIGKILL to the wine process
# this script started), started again on the same data directory, the value still there,
# and the killed finsd's stale channel file replaced by the new one's.
# Usage: windows_finsd.sh WINDOWS_BIN_DIR HOST_BIN_DIR (WINEPREFIX and WINEDEBUG from
# ctest's environment). Every wait is for a condition, bounded in time; every process
# started is ended on exit (only those: wineserver is left to wine).
set -euo pipefail
source "$(dirname "$0")/round_trip_lib.sh"  # windows_test, free_port, wait_for
windows_test "windows finsd" "$1" "$2" "$2/fins" "$1/finsd.exe"
fins() { "$host_bin/fins" --host 127.0.0.1 --port "$port" "$@"; }
values() { fins "$@" --json | grep -o '"values":\[[^]]*\]'; }

# Windows paths for wine: the Unix root is drive Z:.
data="Z:${work}/data"
channel="$work/ctl"  # the channel file, as Linux sees it
control="Z:$channel"
start_finsd() {  # LOG: finsd.exe in the background, its wine process's PID in $finsd_pid
  "$wine" "$bin/finsd.exe" --bind 127.0.0.1 --port "$port" \
    --data-dir "$data" --control "$control" >"$work/$1" 2>&1 &
  finsd_pid=$!
  pids+=("$finsd_pid")
  wait_for 120 grep -q "^listening $port" "$work/$1" || fail "finsd.exe did not listen ($1)"
}
# ctl ARGS...: finsd.exe ctl, its output (CRs dropped) in $out, its exit code in $rc.
ctl() {
  set +e
  out=$(timeout 60 "$wine" "$bin/finsd.exe" ctl "$@" 2>&1 | tr -d '\r')
  rc=${PIPESTATUS[0]}
  set -e
}
# silent_close LINE...: connects to the channel's port, sends the lines; true when finsd
# closes the connection without a byte of answer (timeout's 124 if it stays open).
silent_close() {
  local answer
  exec 3<>"/dev/tcp/127.0.0.1/$(cut -d' ' -f1 "$channel")"
  printf '%s\n' "$@" >&3
  answer=$(timeout 20 cat <&3) || { exec 3<&-; return 1; }
  exec 3<&-
  [[ -z "$answer" ]]
}

port=$(free_port)
start_finsd finsd1.log
check grep -qx "listening $port" <(tr -d '\r' <"$work/finsd1.log")
check fins write D100 4242 >/dev/null
check test "$(values read D100 --as int16)" = '"values":[4242]'
check fins --tcp write D101 -7 --as int16 >/dev/null
check test "$(values --tcp read D100 2 --as int16)" = '"values":[4242,-7]'

# The control channel.
check grep -q "control channel on $control" "$work/finsd1.log"
check grep -Eqx '[0-9]+ [0-9a-f]{32}' "$channel"
check test "$(stat -c %a "$channel" | cut -c3)" = 0  # nothing for others
ctl --socket "$control" status
check test "$rc" -eq 0
check grep -q '"ok":true' <<<"$out"
check grep -q '"mode":"run"' <<<"$out"
check grep -q '"model":"CJ2H-CPU68-EIP"' <<<"$out"
ctl mode program --socket "$control"
check test "$rc" -eq 0
check grep -q '"mode":"program"' <(fins status --json)
token=$(cut -d' ' -f2 "$channel")
check silent_close '{"cmd":"status"}'
check silent_close "${token%?}x" '{"cmd":"status"}'
# Only the right token gets the answer.
check grep -q '"mode":"program"' <(exec 3<>"/dev/tcp/127.0.0.1/$(cut -d' ' -f1 "$channel")"
  printf '%s\n{"cmd":"status"}\n' "$token" >&3; timeout 20 head -n 1 <&3)
ctl --socket "Z:$work/missing" status
check test "$rc" -eq 3
check grep -q "cannot connect to" <<<"$out"
# A live channel file is not taken over: the second finsd.exe stops (exit 3).
set +e
timeout 120 "$wine" "$bin/finsd.exe" --bind 127.0.0.1 --port 0 --control "$control" \
  >"$work/finsd-second.log" 2>&1
rc=$?
set -e
check test "$rc" -eq 3
check grep -q "control channel $control" "$work/finsd-second.log"
ctl --socket "$control" status
check test "$rc" -eq 0

# Retained memory: the acknowledged write survives SIGKILL of finsd.exe.
check fins write D100 777 >/dev/null
kill -9 "$finsd_pid"
wait "$finsd_pid" 2>/dev/null || true
check test -f "$channel"  # left behind by the killed finsd.exe: stale
stale=$(cat "$channel")
port=$(free_port)
start_finsd finsd2.log
check test "$(values read D100 2 --as int16)" = '"values":[777,-7]'
check grep -q "control channel on $control" "$work/finsd2.log"
check test "$(cat "$channel")" != "$stale"
ctl --socket "$control" status
check test "$rc" -eq 0
echo "windows finsd: $passed checks passed"
