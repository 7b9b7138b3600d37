#!/usr/bin/env bash
# fins.exe under wine against the host's Linux finsd on 127.0.0.1 (docs/windows.md):
# FINS/UDP and FINS/TCP reads and writes, probe, discover, watch, and the answer when
# nothing listens. Usage: windows_round_trip.sh WINDOWS_BIN_DIR HOST_BIN_DIR
# (WINEPREFIX and WINEDEBUG from ctest's environment). Every wait is for a condition,
# bounded in time; every process started is ended on exit.
set -euo pipefail
source "$(dirname "$0")/round_trip_lib.sh"  # windows_test, free_port, wait_for
windows_test "windows round trip" "$1" "$2" "$2/finsd" "$1/fins.exe"
# wine's console output ends lines with CR LF: compare without the CR.
fins() { "$wine" "$bin/fins.exe" --host 127.0.0.1 --port "$port" "$@" | tr -d '\r'; }

port=$(free_port)
"$host_bin/finsd" --bind 127.0.0.1 --port "$port" --control "$work/ctl.sock" >"$work/finsd.log" 2>&1 &
pids+=($!)
wait_for 60 grep -q "listening $port" "$work/finsd.log" || fail "finsd did not listen"
values() { fins "$@" --json | grep -o '"values":\[[^]]*\]'; }

check fins write D100 4242 >/dev/null
check test "$(values read D100 --as int16)" = '"values":[4242]'
check fins --tcp write D101 -7 --as int16 >/dev/null
check test "$(values --tcp read D100 2 --as int16)" = '"values":[4242,-7]'
check test "$(fins probe --json | grep -o '"node":"[^"]*"')" = '"node":"0.1.0"'
check test "$(fins discover --hosts 127.0.0.1 --json | grep -c '"host":"127.0.0.1"')" = 1
check test "$(fins watch D100 --count 1 | awk '{print $2, $3}')" = "D100 4242"

# Nothing listening: the same message and exit status as the Linux fins.
set +e
out=$("$wine" "$bin/fins.exe" --host 127.0.0.1 --port 1 read D100 --timeout 1 2>&1 | tr -d '\r')
rc=${PIPESTATUS[0]}
set -e
check test "$rc" = 3
check grep -q "Connection refused" <<<"$out"
echo "windows round trip: $passed checks passed"
