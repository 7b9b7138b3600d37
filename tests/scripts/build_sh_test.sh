#!/usr/bin/env bash
# scripts/build.sh builds what it is asked for. The fuzz tree is configured for real
# (clang-14, FINS_FUZZ=ON) in a scratch directory, and ninja lists the commands the
# build would run instead of running them (FINS_NINJA_ARGS="-t commands"): the fuzzers
# linked must be the ones named, or every fuzzer of fuzz/ when none is. Run by ctest
# (tests/CMakeLists.txt, test "build_sh"); by hand: tests/scripts/build_sh_test.sh
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
for tool in clang++-14 cmake ninja; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool is not installed (the fuzz tree needs it)"; exit 0; }
done
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
failed=0

# The executables under bin/ that `scripts/build.sh fuzz ARGS...` would link, sorted.
linked() {
  FINS_BUILD_DIR="$scratch/build-fuzz" FINS_NINJA_ARGS="-t commands" FINS_JOBS=1 \
    "$root/scripts/build.sh" fuzz "$@" | grep -o -- '-o bin/[A-Za-z0-9_]*' | sed 's|-o bin/||' | sort -u
}
expect() {  # NAME EXPECTED ACTUAL
  if [[ "$2" == "$3" ]]; then
    echo "ok: $1"
  else
    echo "FAILED: $1"; echo "  expected: $(echo $2)"; echo "  actual:   $(echo $3)"; failed=1
  fi
}

# The fuzzers the sources define: fuzz/*.cpp with a libFuzzer entry point.
all=$(grep -l LLVMFuzzerTestOneInput "$root"/fuzz/*.cpp | xargs -n1 basename | sed 's/\.cpp$//' | sort)
[[ $(echo "$all" | wc -l) -ge 12 ]] || { echo "FAILED: fewer than 12 fuzzers in fuzz/"; exit 1; }

expect "one target named: only it" "fuzz_address" "$(linked fuzz_address)"
expect "two targets named: only them" "$(printf 'fuzz_http\nfuzz_tcp')" "$(linked fuzz_tcp fuzz_http)"
# Every fuzzer, and not the seed generator (make_corpus.cpp, a plain program).
expect "no target: every fuzzer" "$all" "$(linked)"
expect "fuzzers.txt (scripts/test.sh's list) is CMake's" "$all" "$(sort "$scratch/build-fuzz/fuzzers.txt")"

if err=$(FINS_BUILD_DIR="$scratch/build-fuzz" FINS_NINJA_ARGS="-t commands" \
    "$root/scripts/build.sh" fuzz fuzz_nothing 2>&1 >/dev/null); then
  echo "FAILED: an unknown target succeeded"; failed=1
elif [[ "$err" != *fuzz_nothing* ]]; then
  echo "FAILED: an unknown target's error does not name it: $err"; failed=1
else
  echo "ok: an unknown target fails and is named"
fi
exit $failed
