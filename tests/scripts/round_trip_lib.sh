# shellcheck shell=bash
# Sourced by the cross builds' round trips (cross_round_trip.sh, the windows_*.sh tests)
# and bench/bridge_peers.sh.
# A free loopback port (UDP and TCP both free: finsd takes both).
free_port() {
  /usr/bin/python3 -c 'import socket
while True:
    t = socket.socket(); t.bind(("127.0.0.1", 0)); p = t.getsockname()[1]
    u = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        u.bind(("127.0.0.1", p)); print(p); break
    except OSError: pass
    finally: u.close(); t.close()'
}
# wait_for SECONDS COMMAND...: until COMMAND succeeds, at most SECONDS (tenths polled).
wait_for() {
  local deadline=$((SECONDS + $1)); shift
  until "$@" >/dev/null 2>&1; do
    ((SECONDS < deadline)) || return 1
    sleep 0.1
  done
}
# round_trip_workdir: $work, a temporary directory, and $pids, the processes a script
# starts; both are cleaned up on exit (each process killed and waited for, only those).
round_trip_workdir() {
  work=$(mktemp -d)
  pids=()
  trap round_trip_cleanup EXIT
}
round_trip_cleanup() {
  local pid
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
# windows_test NAME BIN_DIR HOST_BIN_DIR FILE...: the start of a test under wine
# (tests/scripts/windows_*.sh, given WINDOWS_BIN_DIR HOST_BIN_DIR by ctest): $bin,
# $host_bin and $wine; each FILE (the programs the test runs) must exist; $work and $pids
# (round_trip_workdir); fail MESSAGE (with the last lines of $work's finsd logs), and
# check COMMAND..., which counts into $passed.
windows_test() {
  test_name=$1 bin=$2 host_bin=$3
  shift 3
  wine=/usr/lib/wine/wine64
  local file
  for file in "$@"; do
    [[ -e "$file" ]] || { echo "$test_name: no $file" >&2; exit 1; }
  done
  round_trip_workdir
  passed=0
  fail() { echo "$test_name: $*" >&2; tail -n 20 "$work"/finsd*.log >&2 2>/dev/null || true; exit 1; }
  check() { if "$@"; then passed=$((passed + 1)); else fail "failed: $*"; fi; }
}
