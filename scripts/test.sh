#!/usr/bin/env bash
# The whole test suite, as CI runs it: installs what is missing, then
#   1. an ASan+UBSan build with warnings as errors, and every test under it (unit,
#      loopback integration, CLI, tshark conformance, SIGKILL);
#   2. a short soak of the ASan+UBSan finsd (scripts/soak.sh: verifying UDP and TCP
#      clients, garbage datagrams, connection churn; counts as one test);
#   3. the libFuzzer targets over every decoder, the dispatcher and a whole session,
#      briefly each, from the committed corpus (fuzz/corpus/).
# (One instrumented build instead of a Release one and an instrumented one keeps the
# suite inside its time budget on 2 cores; scripts/run.sh builds Release.)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
fuzz_seconds=${FINS_FUZZ_SECONDS:-20}
soak_seconds=${FINS_SOAK_SECONDS:-20}
"$root/scripts/deps.sh"

summary=()
run_ctest() {
  local dir=$1 label=$2 log
  log=$(mktemp)
  if ctest --test-dir "$dir" -j 2 --output-on-failure --timeout 300 | tee "$log"; then :; else
    summary+=("$label: FAILED"); tail -n 3 "$log"; rm -f "$log"; return 1
  fi
  summary+=("$label: $(grep -E 'tests passed' "$log" | tail -n 1)")
  rm -f "$log"
}

echo "== ASan+UBSan build"
"$root/scripts/build.sh" asan
echo "== ASan+UBSan tests"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  run_ctest build-asan asan

echo "== soak (${soak_seconds}s, ASan+UBSan finsd)"
soak_log=$(mktemp)
if "$root/scripts/soak.sh" asan --seconds "$soak_seconds" --interval 5 | tee "$soak_log"; then :; else
  summary+=("soak: FAILED"); rm -f "$soak_log"; printf '%s\n' "${summary[@]}"; exit 1
fi
soak_ok=1
summary+=("soak: $(grep -E '^soak: [0-9]+ s,' "$soak_log" | tail -n 1 | sed 's/^soak: //')")
rm -f "$soak_log"

echo "== fuzz (${fuzz_seconds}s per target)"
"$root/scripts/build.sh" fuzz
fuzz_ok=0
for target in fuzz_frame fuzz_tcp fuzz_address fuzz_dispatch fuzz_session fuzz_files; do
  corpus=$(mktemp -d)
  seeds="$root/fuzz/corpus/$target"
  [[ -d "$seeds" ]] && cp -r "$seeds/." "$corpus/"
  if "$root/build-fuzz/bin/$target" -max_total_time="$fuzz_seconds" -print_final_stats=0 \
      "$corpus" >"$corpus.log" 2>&1; then
    fuzz_ok=$((fuzz_ok + 1))
    echo "$target: $(grep -Eo 'Done [0-9]+ runs in [0-9]+ second' "$corpus.log" | tail -n 1)s"
  else
    echo "$target FAILED"; tail -n 40 "$corpus.log"; exit 1
  fi
  rm -rf "$corpus" "$corpus.log"
done
summary+=("fuzz: $fuzz_ok targets ran clean")

echo "== summary"
printf '%s\n' "${summary[@]}"
asan_total=$(ctest --test-dir build-asan -N | grep -Eo 'Total Tests: [0-9]+' | grep -Eo '[0-9]+')
echo "$((asan_total + soak_ok + fuzz_ok)) passed, 0 failed"
