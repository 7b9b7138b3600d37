#!/usr/bin/env bash
# Runs one Windows program under wine for ctest: tests/scripts/wine_test.sh PROGRAM.exe [ARGS...]
# Its output goes through a file, then to ctest. The first program of a wine session
# starts wine's own processes (services.exe, explorer.exe, ...), which inherit its
# standard output and live until the session's last program ends; ctest reads a test's
# output until no process holds it, so a 0.3 s test_codec.exe started first stayed
# "running" for the 78 s of test_client_lossy beside it, and held one of ctest's two
# slots all that time.
set -u
out=$(mktemp)
trap 'rm -f "$out"' EXIT
/usr/lib/wine/wine64 "$@" >"$out" 2>&1
status=$?
cat "$out"
exit "$status"
