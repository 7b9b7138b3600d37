# shellcheck shell=bash
# Sourced by the cross builds' round trips (cross_round_trip.sh, windows_round_trip.sh,
# windows_finsd.sh) and bench/bridge_peers.sh.
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
