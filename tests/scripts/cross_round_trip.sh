#!/usr/bin/env bash
# One round trip of a cross build's own programs (arm64 under qemu-user): the emulated
# finsd answers the emulated fins over FINS/UDP and FINS/TCP on 127.0.0.1, and the emulated
# fins-bridge publishes a value the PLC holds to the host's mosquitto and writes an MQTT
# setpoint back, read back by fins. Usage: cross_round_trip.sh BIN_DIR (FINS_EMULATOR: the
# command line that runs a target binary, e.g. "qemu-aarch64 -L /").
# Every wait is for a condition, bounded in time; every process started is ended on exit.
set -euo pipefail
bin=$1
read -r -a emu <<<"${FINS_EMULATOR:-}"
source "$(dirname "$0")/round_trip_lib.sh"  # free_port, wait_for, round_trip_workdir
round_trip_workdir
fail() { echo "cross round trip: $*" >&2; for f in "$work"/*.log; do echo "== $f"; tail -n 20 "$f"; done >&2; exit 1; }
run() { "${emu[@]}" "$bin/$1" "${@:2}"; }

fins_port=$(free_port)
# Started without the run function: $! must be the program's own PID (a function in the
# background is a subshell, and killing it left the emulated program running).
XDG_RUNTIME_DIR=$work "${emu[@]}" "$bin/finsd" --bind 127.0.0.1 --port "$fins_port" >"$work/finsd.log" 2>&1 &
pids+=($!)
wait_for 60 grep -q "listening $fins_port" "$work/finsd.log" || fail "finsd did not listen"
passed=0
check() { if "$@"; then passed=$((passed + 1)); else fail "failed: $*"; fi; }

# FINS/UDP and FINS/TCP through the emulated client.
check run fins --host 127.0.0.1 --port "$fins_port" write D100 4242 >/dev/null
values() { run fins --host 127.0.0.1 --port "$fins_port" "$@" --json | grep -o '"values":\[[^]]*\]'; }
check test "$(values read D100 --as int16)" = '"values":[4242]'
check test "$(values --tcp read D100 --as int16)" = '"values":[4242]'

# The bridge through the host's broker.
mqtt_port=$(free_port)
cat >"$work/mosquitto.conf" <<CONF
listener $mqtt_port 127.0.0.1
allow_anonymous true
CONF
mosquitto -c "$work/mosquitto.conf" >"$work/mosquitto.log" 2>&1 &
pids+=($!)
wait_for 30 mosquitto_sub -p "$mqtt_port" -t probe -W 1 -E || fail "mosquitto did not start"
cat >"$work/bridge.toml" <<CONF
[mqtt]
port = $mqtt_port
topic_prefix = "cross"
[[plc]]
name = "press1"
host = "127.0.0.1"
port = $fins_port
dest = "0.1.0"
[[plc.group]]
name = "fast"
interval_ms = 100
publish = "always"
tags = [ { name = "speed", address = "D100", type = "int16" },
         { name = "temp", address = "D200", type = "float", writable = true, min = -50, max = 500 } ]
CONF
mosquitto_sub -p "$mqtt_port" -t 'cross/#' -v >"$work/sub.log" 2>&1 &
pids+=($!)
"${emu[@]}" "$bin/fins-bridge" --config "$work/bridge.toml" --instance cross --log-level warn \
  >"$work/bridge.log" 2>&1 &
pids+=($!)
check wait_for 60 grep -q 'cross/press1/fast .*"speed":4242' "$work/sub.log"
wait_for 30 grep -q 'cross/press1/status .*"online"' "$work/sub.log" || fail "PLC not online"
mosquitto_pub -p "$mqtt_port" -q 1 -t cross/press1/write -m '{"id":"w1","tag":"temp","value":21.5}'
check wait_for 60 grep -q 'cross/press1/write/response .*"ok":true' "$work/sub.log"
check test "$(values read D200 --as float)" = '"values":[21.5]'
echo "cross round trip: $passed checks passed"
