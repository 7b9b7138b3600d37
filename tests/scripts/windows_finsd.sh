#!/usr/bin/env bash
# finsd.exe under wine answering the host's Linux fins on 127.0.0.1 (docs/windows.md):
# "listening P" as finsd prints it; D100 written and read over FINS/UDP and FINS/TCP;
# retained memory: a write acknowledged, finsd.exe killed (SIGKILL to the wine process
# this script started), started again on the same data directory, the value still there;
# The control channel: Wine has no AF_UNIX sockets (WSAEAFNOSUPPORT, which Windows 10
# has), so finsd.exe under wine runs without one, says so, and `finsd.exe ctl status`
# answers "cannot connect" with a non-zero exit instead of hanging or crashing.
# Usage: windows_finsd.sh WINDOWS_BIN_DIR HOST_BIN_DIR (WINEPREFIX and WINEDEBUG from
# ctest's environment). Every wait is for a condition, bounded in time; every process
# started is ended on exit (only those: wineserver is left to wine).
set -euo pipefail
bin=$1
host_bin=$2
wine=/usr/lib/wine/wine64
[[ -x "$host_bin/fins" ]] || { echo "windows finsd: no host fins in $host_bin" >&2; exit 1; }
[[ -f "$bin/finsd.exe" ]] || { echo "windows finsd: no finsd.exe in $bin" >&2; exit 1; }
source "$(dirname "$0")/round_trip_lib.sh"  # free_port, wait_for, round_trip_workdir
round_trip_workdir
fail() { echo "windows finsd: $*" >&2; tail -n 20 "$work"/finsd*.log >&2 || true; exit 1; }
fins() { "$host_bin/fins" --host 127.0.0.1 --port "$port" "$@"; }
values() { fins "$@" --json | grep -o '"values":\[[^]]*\]'; }
passed=0
check() { if "$@"; then passed=$((passed + 1)); else fail "failed: $*"; fi; }

# Windows paths for wine: the Unix root is drive Z:.
data="Z:${work}/data"
control="Z:${work}/ctl.sock"  # finsd ctl's --socket: nothing listens there under wine
start_finsd() {  # LOG: finsd.exe in the background, its wine process's PID in $finsd_pid
  "$wine" "$bin/finsd.exe" --bind 127.0.0.1 --port "$port" \
    --data-dir "$data" >"$work/$1" 2>&1 &
  finsd_pid=$!
  pids+=("$finsd_pid")
  wait_for 120 grep -q "^listening $port" "$work/$1" || fail "finsd.exe did not listen ($1)"
}

port=$(free_port)
start_finsd finsd1.log
check grep -qx "listening $port" <(tr -d '\r' <"$work/finsd1.log")
check fins write D100 4242 >/dev/null
check test "$(values read D100 --as int16)" = '"values":[4242]'
check fins --tcp write D101 -7 --as int16 >/dev/null
check test "$(values --tcp read D100 2 --as int16)" = '"values":[4242,-7]'

# finsd ctl under wine: no channel, a clear answer (see above).
check grep -q "no control channel" "$work/finsd1.log"
set +e
ctl=$(timeout 60 "$wine" "$bin/finsd.exe" ctl --socket "$control" status 2>&1 | tr -d '\r')
rc=${PIPESTATUS[0]}
set -e
check test "$rc" -ne 0 -a "$rc" -ne 124
check grep -q "cannot connect to" <<<"$ctl"

# Retained memory: the acknowledged write survives SIGKILL of finsd.exe.
check fins write D100 777 >/dev/null
kill -9 "$finsd_pid"
wait "$finsd_pid" 2>/dev/null || true
port=$(free_port)
start_finsd finsd2.log
check test "$(values read D100 2 --as int16)" = '"values":[777,-7]'
echo "windows finsd: $passed checks passed"
