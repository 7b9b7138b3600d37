# Sourced by scripts/consumers.sh and scripts/package.sh: `finsd_start FINSD ARGS...`
# starts finsd with --port 0 in the background and sets finsd_pid and finsd_port from
# its "listening <port>" line (each line waited for at most 20 s, at most 100 lines of
# log before it). `finsd_stop` sends SIGTERM and waits for it.
finsd_start() {
  local line="" n
  exec {finsd_fd}< <(exec "$@" --port 0)
  finsd_pid=$!
  for ((n = 0; n < 100; n++)); do
    IFS= read -r -t 20 -u "$finsd_fd" line || break
    [[ "$line" == listening* ]] && break
  done
  if [[ "$line" != listening* ]]; then
    echo "finsd did not start: ${line:-no output}" >&2
    return 1
  fi
  finsd_port=${line#listening }
  # Keep reading its log so a full pipe never blocks it.
  cat <&"$finsd_fd" >/dev/null &
  finsd_drain=$!
}
finsd_stop() {
  kill -TERM "$finsd_pid" 2>/dev/null || true
  wait "$finsd_pid" 2>/dev/null || true
  wait "$finsd_drain" 2>/dev/null || true
  exec {finsd_fd}<&-
}
