#!/usr/bin/env bash
# A plant in finsd.exe under wine (issue 28: plants; docs/networks.md "A plant of several
# networks"): examples/three-networks.toml as a user runs it. The host's Linux fins, at
# router-a's address 127.0.1.1, writes D100 of line-3 (node 3.5) two networks away
# through both routers and reads it back; line-3 answers the value at its own address,
# router-a's own D100 is untouched, a unit answers with its own status, and a network in
# no routing table is the relay error (0501 from router-a, fins exit 4).
# Two things differ from Linux, both wine's (docs/windows.md): wine 8 binds a UDP socket
# asked for 127.0.1.1:P as 0.0.0.0:P (`ss -uan` shows it), so units on several loopback
# addresses cannot share a port (the second bind fails, WSAEADDRINUSE) and a UDP answer
# leaves from 127.0.0.1, which a client that sent to 127.0.1.1 does not take. So each unit
# has a free port of its own instead of 9600, and the client speaks FINS/TCP, whose
# listeners wine binds as asked.
# Usage: windows_plant.sh WINDOWS_BIN_DIR HOST_BIN_DIR SOURCE_DIR (WINEPREFIX and
# WINEDEBUG from ctest's environment). Every wait is for a condition, bounded in time;
# the one finsd.exe started is ended on exit.
set -euo pipefail
source_dir=$3
source "$(dirname "$0")/round_trip_lib.sh"  # windows_test, free_port, wait_for
windows_test "windows plant" "$1" "$2" "$2/fins" "$1/finsd.exe" "$3/examples/three-networks.toml"

# The five units' ports, in the file's order: router-a 1.1 and 2.1, router-b 2.2 and
# 3.2, line-3 3.5.
ports=()
while ((${#ports[@]} < 5)); do
  p=$(free_port)
  [[ " ${ports[*]} " == *" $p "* ]] || ports+=("$p")
done
awk -v ports="${ports[*]}" 'BEGIN { n = split(ports, p, " ") }
  /^ *port *= *9600 *$/ { sub(/9600/, p[++i]) } { print }' \
  "$source_dir/examples/three-networks.toml" >"$work/plant.toml"
check test "$(grep -c '^ *port = 9600' "$work/plant.toml")" -eq 0
port=${ports[0]}       # router-a's unit 0, 127.0.1.1: what the client talks to
line3_port=${ports[4]} # line-3, 127.0.3.5
fins() { "$host_bin/fins" --tcp --port "$port" "$@"; }
values() { fins "$@" --json | grep -o '"values":\[[^]]*\]'; }
line3() { "$host_bin/fins" --tcp --port "$line3_port" --host 127.0.3.5 "$@"; }
# Windows paths for wine: the Unix root is drive Z:.
"$wine" "$bin/finsd.exe" --config "Z:$work/plant.toml" --control "Z:$work/ctl" \
  >"$work/finsd.log" 2>&1 &
pids+=("$!")
wait_for 120 grep -q "^listening $port" "$work/finsd.log" || fail "finsd.exe did not listen"

check fins --host 127.0.1.1 --dest 3.5.0 write D100 4242 >/dev/null
check grep -q '"values":\[4242\]' <(line3 read D100 --as int16 --json)
check test "$(values --host 127.0.1.1 read D100)" = '"values":[0]'
check fins --host 127.0.1.1 --dest 3.5.0 write D101 -7 --as int16 >/dev/null
check test "$(values --host 127.0.1.1 --dest 3.5.0 read D100 2 --as int16)" \
  = '"values":[4242,-7]'
check grep -q '"mode":"run"' <(line3 status --json)
set +e
out=$(fins --host 127.0.1.1 --dest 9.5.0 read D100 2>&1)
rc=$?
set -e
check test "$rc" -eq 4
check grep -q '0x0501' <<<"$out"
check grep -q 'router at network 1 node 1' <<<"$out"
echo "windows plant: $passed checks passed"
