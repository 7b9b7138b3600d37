#!/usr/bin/env bash
# Regenerates the fuzz seeds in fuzz/corpus/<target>/ from the tests' own traffic:
#   1. runs the server unit tests and the FINS/TCP wire tests with FINS_FUZZ_DUMP set,
#      so every frame and stream they send is written out (fuzz/corpus_dump.hpp);
#   2. fuzz_make_corpus turns that dump and tests/vectors/ into each target's input
#      format;
#   3. each target merges the candidates into its committed corpus (-merge=1 keeps
#      only the inputs that add coverage), so the corpus grows and never shrinks here.
# Run from anywhere; commit what it adds. Builds build-asan/ and build-fuzz/ as needed.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$root/scripts/build.sh" asan test_server test_integration >/dev/null
"$root/scripts/build.sh" fuzz >/dev/null
ninja -C "$root/build-fuzz" fuzz_make_corpus >/dev/null
FINS_FUZZ_DUMP="$work/dump" "$root/build-asan/bin/test_server" >/dev/null
FINS_FUZZ_DUMP="$work/dump" "$root/build-asan/bin/test_integration" \
  --gtest_filter='TcpWire.*' >/dev/null 2>&1
"$root/build-fuzz/bin/fuzz_make_corpus" "$work/dump" "$root/tests/vectors" "$work/seeds"
for target in fuzz_frame fuzz_tcp fuzz_address fuzz_dispatch fuzz_session; do
  mkdir -p "$root/fuzz/corpus/$target"
  before=$(ls "$root/fuzz/corpus/$target" | wc -l)
  [[ -d "$work/seeds/$target" ]] || continue
  "$root/build-fuzz/bin/$target" -merge=1 "$root/fuzz/corpus/$target" "$work/seeds/$target" \
    >"$work/$target.log" 2>&1 || { tail -n 30 "$work/$target.log"; exit 1; }
  echo "$target: $before -> $(ls "$root/fuzz/corpus/$target" | wc -l) seeds"
done
