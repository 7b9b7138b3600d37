#!/usr/bin/env bash
# A bounded soak of finsd (bench/soak.cpp): builds finsd and fins_soak, then runs them.
#   scripts/soak.sh [release|asan] [fins_soak options]
#   scripts/soak.sh --minutes 10            # the long run the README quotes (Release)
#   scripts/soak.sh asan --seconds 20       # what scripts/test.sh runs
# fins_soak prints a report every --interval seconds and exits non-zero on any
# mismatch, a crash or stall of finsd, RSS growth beyond --max-rss-growth-mib, or an
# unclean shutdown.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
kind=release
if [[ "${1:-}" == release || "${1:-}" == asan ]]; then kind=$1; shift; fi
case "$kind" in
  release) dir=build ;;
  asan)
    dir=build-asan
    # A small quarantine: ASan's default 256 MiB of freed memory held back would look
    # like growth to the RSS bound. Leaks are reported when finsd exits on SIGTERM.
    export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}:quarantine_size_mb=4
    export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
    ;;
esac
"$root/scripts/build.sh" "$kind" finsd fins_soak
exec "$root/$dir/bin/fins_soak" --finsd "$root/$dir/bin/finsd" "$@"
