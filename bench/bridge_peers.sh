#!/usr/bin/env bash
# fins-bridge against the Node.js peer (issue 27, docs/benchmarks.md "fins-bridge against
# the Node.js peers"), on loopback only. Starts a mosquitto on a free port and a finsd plant
# of --plcs CPU Units (127.0.60.1 ... on one free port, FINS node = the last octet), each
# running a scenario that moves 100 int16 words D0-D99 every 100 ms tick; then runs each
# gateway, one after the other, for the same time:
#   bridge  fins-bridge (build/bin, Release): 100 int16 tags D0-D99 per PLC every
#           --interval-ms, publish = "always", JSON (one 01 01 frame a cycle);
#   node    bench/peers/fins_peer.js: omron-fins + MQTT.js doing the same.
# After --warmup seconds, fins_bridge_peers_counter (an independent libmosquitto
# subscriber) counts every value that reaches it for --seconds and measures the gateway's
# CPU and RSS (and finsd's and mosquitto's) over the same window. Prints one table row per
# gateway and one JSON line; exits 1 if a gateway delivered nothing.
#
#   ./scripts/build.sh release fins-bridge finsd fins_bridge_peers_counter
#   bench/bridge_peers.sh [--plcs 1000] [--seconds 20] [--warmup 5] [--interval-ms 100]
#                         [--gateways "bridge node"] [--keep]
# FINS_BUILD_DIR: the tree holding bin/ (default build). Not a test: ctest does not run it.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${FINS_BUILD_DIR:-$root/build}
plcs=1000 seconds=20 warmup=5 interval_ms=100 gateways="bridge node" keep=0 tags=100
net3=60  # the third octet of the first unit's address: 127.0.60.1
while (($#)); do
  case "$1" in
    --plcs) plcs=$2; shift 2 ;;
    --seconds) seconds=$2; shift 2 ;;
    --warmup) warmup=$2; shift 2 ;;
    --interval-ms) interval_ms=$2; shift 2 ;;
    --gateways) gateways=$2; shift 2 ;;
    --keep) keep=1; shift ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
    *) echo "bridge_peers.sh: unknown option $1 (--help)" >&2; exit 2 ;;
  esac
done
if ((plcs < 1 || plcs > 1000)); then echo "bridge_peers.sh: --plcs 1-1000" >&2; exit 2; fi

for exe in finsd fins-bridge fins_bridge_peers_counter; do
  if [[ ! -x $build/bin/$exe ]]; then
    echo "bridge_peers.sh: no $build/bin/$exe: ./scripts/build.sh release fins-bridge finsd fins_bridge_peers_counter" >&2
    exit 2
  fi
done
command -v mosquitto >/dev/null || PATH=$PATH:/usr/sbin
command -v mosquitto >/dev/null || { echo "bridge_peers.sh: needs mosquitto" >&2; exit 2; }
if [[ " $gateways " == *" node "* ]]; then
  command -v node >/dev/null || { echo "bridge_peers.sh: needs node and npm" >&2; exit 2; }
  # The peers' npm packages, at the versions of bench/peers/package-lock.json.
  [[ -d $root/bench/peers/node_modules ]] ||
    npm ci --prefix "$root/bench/peers" --no-audit --no-fund >&2
fi

tmp=$(mktemp -d /tmp/bridge-peers.XXXXXX)
pids=()
cleanup() {
  local p
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do stop_pid "$p"; done
  if ((keep)); then echo "bridge_peers.sh: files kept in $tmp" >&2; else rm -rf "$tmp"; fi
}
# SIGTERM sent: waits at most 10 s for the process, then SIGKILL.
stop_pid() {
  local p=$1 i
  for ((i = 0; i < 100; i++)); do
    kill -0 "$p" 2>/dev/null || { wait "$p" 2>/dev/null || true; return 0; }
    sleep 0.1
  done
  kill -KILL "$p" 2>/dev/null || true
  wait "$p" 2>/dev/null || true
}
trap cleanup EXIT

source "$root/tests/scripts/round_trip_lib.sh"  # free_port, wait_for
tcp_open() { (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
unit_ip() { echo "127.0.$((net3 + $1 / 250)).$((1 + $1 % 250))"; }

echo "bridge_peers.sh: $plcs PLCs x $tags int16 every $interval_ms ms, ${warmup} s warm-up + ${seconds} s per gateway; $(uptime)" >&2

# The broker.
mqtt_port=$(free_port)
cat >"$tmp/mosquitto.conf" <<EOF
persistence false
listener $mqtt_port 127.0.0.1
allow_anonymous true
max_queued_messages 100000
EOF
mosquitto -c "$tmp/mosquitto.conf" >"$tmp/mosquitto.log" 2>&1 &
mosquitto_pid=$!
pids+=("$mosquitto_pid")
wait_for 10 tcp_open "$mqtt_port" || { echo "mosquitto did not start:" >&2; cat "$tmp/mosquitto.log" >&2; exit 1; }

# The plant: every unit runs the same scenario, D0-D99 sawtooths 0-30000 over 300 s, so
# each word moves by 10 at every 100 ms tick.
{
  echo '[scenario]'
  echo 'tick_ms = 100'
  echo 'time = "real"'
  for ((k = 0; k < tags; k++)); do
    printf '[[scenario.signal]]\naddress = "D%d"\ntype = "int16"\nkind = "sawtooth"\n' "$k"
    printf 'min = 0\nmax = 30000\nperiod_s = 300\nphase_s = %d\n' $((3 * k))
  done
} >"$tmp/scenario.toml"
fins_port=$(free_port)
{
  echo 'log_level = "warn"'
  for ((i = 0; i < plcs; i++)); do
    printf '[[plc]]\nname = "p%d"\n  [[plc.ethernet]]\n  unit = 0\n  network = %d\n' "$i" $((1 + i / 250))
    printf '  bind = "%s"\n  port = %d\n  [plc.scenario]\n  file = "scenario.toml"\n' "$(unit_ip "$i")" "$fins_port"
  done
} >"$tmp/plant.toml"
"$build/bin/finsd" --config "$tmp/plant.toml" --log-level warn >"$tmp/finsd.log" 2>&1 &
finsd_pid=$!
pids+=("$finsd_pid")
wait_for 120 grep -q listening "$tmp/finsd.log" || { echo "finsd did not start:" >&2; tail "$tmp/finsd.log" >&2; exit 1; }

# fins-bridge's configuration: the same 100 words as 100 int16 tags, `always`.
{
  printf '[bridge]\nstats_s = 2\n[mqtt]\nhost = "127.0.0.1"\nport = %d\n' "$mqtt_port"
  printf 'topic_prefix = "bridge"\nqueue_limit = 100000\n'
  tag_list=""
  for ((k = 0; k < tags; k++)); do
    sep=""; ((k == 0)) || sep=","
    tag_list+="$sep{name=\"t$k\",address=\"D$k\",type=\"int16\"}"
  done
  for ((i = 0; i < plcs; i++)); do
    printf '[[plc]]\nname = "p%d"\nhost = "%s"\nport = %d\ndest = "0.%d.0"\n' "$i" "$(unit_ip "$i")" "$fins_port" $((1 + i % 250))
    printf '[[plc.group]]\nname = "g"\ninterval_ms = %d\npublish = "always"\ntags = [%s]\n' "$interval_ms" "$tag_list"
  done
} >"$tmp/bridge.toml"

# run_gateway NAME PREFIX COMMAND...: the gateway's run; its JSON line in $tmp/NAME.json.
run_gateway() {
  local name=$1 prefix=$2; shift 2
  local load
  load=$(cut -d' ' -f1-3 /proc/loadavg)
  "$@" >"$tmp/$name.log" 2>&1 &
  local pid=$!
  pids+=("$pid")
  sleep "$warmup"
  if ! kill -0 "$pid" 2>/dev/null; then
    echo "bridge_peers.sh: $name exited during the warm-up:" >&2
    tail "$tmp/$name.log" >&2
    echo "{\"label\":\"$name\",\"values\":0,\"values_per_s\":0,\"load\":\"$load\"}" >"$tmp/$name.json"
    return 0
  fi
  "$build/bin/fins_bridge_peers_counter" --port "$mqtt_port" --topic "$prefix/#" \
    --seconds "$seconds" --label "$name" --watch "gateway=$pid" --watch "finsd=$finsd_pid" \
    --watch "mosquitto=$mosquitto_pid" >"$tmp/$name.raw" || true
  kill -TERM "$pid" 2>/dev/null || true
  stop_pid "$pid"
  LOAD=$load /usr/bin/python3 -c 'import json, os, sys
line = open(sys.argv[1]).read().strip()
j = json.loads(line) if line else {"label": sys.argv[2], "values": 0, "values_per_s": 0}
j["load"] = os.environ["LOAD"]
print(json.dumps(j))' "$tmp/$name.raw" "$name" >"$tmp/$name.json"
}

for g in $gateways; do
  case "$g" in
    bridge) run_gateway bridge bridge "$build/bin/fins-bridge" --config "$tmp/bridge.toml" \
      --instance peers --log-level warn ;;
    node) run_gateway node node node "$root/bench/peers/fins_peer.js" --plcs "$plcs" \
      --fins-port "$fins_port" --net "127.0.$net3" --mqtt-port "$mqtt_port" --prefix node \
      --interval-ms "$interval_ms" --tags "$tags" ;;
    *) echo "bridge_peers.sh: unknown gateway $g (bridge, node)" >&2; exit 2 ;;
  esac
done

files=()
for g in $gateways; do files+=("$tmp/$g.json"); done
PLCS=$plcs TAGS=$tags INTERVAL=$interval_ms SECONDS_=$seconds /usr/bin/python3 - "${files[@]}" <<'EOF'
import json, os, sys
rows = [json.load(open(f)) for f in sys.argv[1:]]
plcs, tags, interval = int(os.environ["PLCS"]), int(os.environ["TAGS"]), int(os.environ["INTERVAL"])
target = plcs * tags * 1000 / interval
def proc(r, name, key):
    return r.get("processes", {}).get(name, {}).get(key, -1)
print(f"{plcs} PLCs x {tags} int16 every {interval} ms: {target:,.0f} values/s expected")
print("| gateway | load avg | values/s delivered (min-max in a second) | overruns (stats span) "
      "| CPU (% of a core) | values per core-second | RSS | latency ts->subscriber p50 / p99 "
      "| finsd CPU | mosquitto CPU | subscriber CPU | tag errors |")
print("| --- " * 12 + "|")
for r in rows:
    cpu = proc(r, "gateway", "cpu_pct")
    vps = r.get("values_per_s", 0)
    r["values_per_core_s"] = vps / (cpu / 100) if cpu > 0 else 0
    st = r.get("stats", {})
    lat = r.get("latency_ms", {})
    print(f"| {r['label']} | {r.get('load', '')} | {vps:,.0f} ({r.get('values_per_s_min', 0):,}-"
          f"{r.get('values_per_s_max', 0):,}) | {st.get('overruns', '-')} ({st.get('span_s', 0):.0f} s) "
          f"| {cpu:.1f} % | {r['values_per_core_s'] / 1e6:.2f} M | {proc(r, 'gateway', 'rss_mib'):.0f} MiB "
          f"| {lat.get('p50', -1):.1f} / {lat.get('p99', -1):.1f} ms | {proc(r, 'finsd', 'cpu_pct'):.1f} % "
          f"| {proc(r, 'mosquitto', 'cpu_pct'):.1f} % | {proc(r, 'counter', 'cpu_pct'):.1f} % "
          f"| {r.get('tag_errors', 0)} |")
print(json.dumps({"plcs": plcs, "tags": tags, "interval_ms": interval,
                  "seconds": float(os.environ["SECONDS_"]), "gateways": rows}))
sys.exit(1 if any(r.get("values", 0) == 0 for r in rows) else 0)
EOF
