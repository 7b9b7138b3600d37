#!/usr/bin/env bash
# fins.exe under wine, verb by verb, against the host's Linux finsd (issue 28: "fins with
# every verb"): each command runs with the Linux fins and then with fins.exe, with
# --json; both must end with the same exit status and print the same text (CR LF from
# wine's console taken as LF). Verbs whose answer moves with time (the clock, cycle
# times, the access log's times) are compared by exit status and the fields present.
# Mutating verbs write the same values twice, so the second run meets the state the first
# left, as the Linux fins did before it. Serial-only verbs are in windows_host_link.sh
# (Host Link, the Serial Gateway and `modbus` need a COM port).
# Usage: windows_fins_verbs.sh WINDOWS_BIN_DIR HOST_BIN_DIR (WINEPREFIX and WINEDEBUG from
# ctest's environment). Every wait is for a condition, bounded in time; every process
# started is ended on exit.
set -euo pipefail
source "$(dirname "$0")/round_trip_lib.sh"  # windows_test, free_port, wait_for
windows_test "windows fins verbs" "$1" "$2" "$2/finsd" "$2/fins" "$1/fins.exe"

port=$(free_port)
"$host_bin/finsd" --bind 127.0.0.1 --port "$port" --control "$work/ctl.sock" \
  --data-dir "$work/data" >"$work/finsd.log" 2>&1 &
pids+=($!)
wait_for 60 grep -q "listening $port" "$work/finsd.log" || fail "finsd did not listen"

# run PROGRAM ARGS...: its standard output in $out, its standard error in $err (CRs
# dropped: the two streams are kept apart, as wine flushes them in another order), its
# exit status in $rc.
run() {
  local program=$1
  shift
  set +e
  if [[ "$program" == linux ]]; then
    "$host_bin/fins" --host 127.0.0.1 --port "$port" --json "$@" >"$work/out" 2>"$work/err"
  else
    "$wine" "$bin/fins.exe" --host 127.0.0.1 --port "$port" --json "$@" >"$work/out" 2>"$work/err"
  fi
  rc=$?
  set -e
  out=$(tr -d '\r' <"$work/out")
  err=$(tr -d '\r' <"$work/err")
}
# same ARGS...: the Linux fins and fins.exe print the same and end the same.
same() {
  local linux_out linux_err linux_rc
  run linux "$@"
  linux_out=$out linux_err=$err linux_rc=$rc
  run windows "$@"
  [[ "$rc" == "$linux_rc" ]] || fail "$*: exit $rc under wine, $linux_rc on Linux ($out $err)"
  [[ "$out" == "$linux_out" ]] || fail "$*: under wine '$out', on Linux '$linux_out'"
  [[ "$err" == "$linux_err" ]] || fail "$*: under wine '$err' on stderr, on Linux '$linux_err'"
  passed=$((passed + 1))
}
# alike ARGS...: the same exit status, and the same JSON keys in the same order.
alike() {
  local linux_keys linux_rc
  run linux "$@"
  linux_keys=$(grep -o '"[a-z_]*":' <<<"$out" || true) linux_rc=$rc
  run windows "$@"
  [[ "$rc" == "$linux_rc" ]] || fail "$*: exit $rc under wine, $linux_rc on Linux ($out $err)"
  [[ "$(grep -o '"[a-z_]*":' <<<"$out" || true)" == "$linux_keys" ]] ||
    fail "$*: other fields under wine ($out)"
  passed=$((passed + 1))
}

same write D200 1 2 3
same read D200 3
same read D200 2 --as int32
same fill D300 4 7
same transfer D200 D400 3
same read-multi D200 D400 D301
same raw 0101 82000000 0001
same probe
same cpu-data
same connections
same status
same messages
same fal 9
same error-log
same param-read plc-setup 0 4
same program-read 0 16
same stop
same force set CIO10.13
same read-multi CIO10.13
same force-cancel
same run
same --source 0.10.0 access acquire
same --source 0.10.0 access release
same error-clear all
same loop-read 0 0 1
same param-clear routing
same param-read routing 0 2
# Files on the host by relative name: the Linux fins and fins.exe (wine maps the Unix
# working directory to its Z: drive) name the same file.
cd "$work"
head -c 3000 /dev/urandom >upload.bin
same files put --force upload.bin /UP.BIN
same files put upload.bin /UP.BIN  # it exists: the end code, exit 4
same files ls
rm -f UP.BIN
run windows files get /UP.BIN
cmp -s upload.bin UP.BIN || fail "fins.exe files get: the file differs"
rm -f UP.BIN
same files get /UP.BIN
cmp -s upload.bin UP.BIN || fail "files get: the file differs"
same program-read 0 16
head -c 16 /dev/zero >program.bin
same program-write program.bin
same program-clear
same read D40000 1      # beyond the area: the end code, exit 4
same read               # a usage error, exit 2
same access steal       # exit 2
alike clock
alike cycle-time
alike access-log
echo "windows fins verbs: $passed verbs alike"
