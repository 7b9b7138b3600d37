#!/usr/bin/env bash
# scripts/run.sh builds the finskit Python module beside finsd (issue 26 point 12), for
# Debian's /usr/bin/python3 whatever python3 comes first on PATH. The release tree is
# configured for real in a scratch directory and ninja lists the commands it would run
# (FINS_NINJA_ARGS="-t commands"), so nothing is compiled; run.sh stops before starting
# finsd (FINS_RUN_BUILD_ONLY). Run by ctest (tests/CMakeLists.txt, test "run_sh"); by hand:
# tests/scripts/run_sh_test.sh
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
for tool in cmake ninja /usr/bin/python3; do
  command -v "$tool" >/dev/null || { echo "SKIP: $tool is not installed"; exit 0; }
done
# run.sh installs missing packages first: only when none is missing does this test run it.
while read -r pkg; do
  [[ -z "$pkg" || "$pkg" == \#* ]] && continue
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" ||
    { echo "SKIP: $pkg is not installed (run.sh would install it)"; exit 0; }
done < "$root/scripts/debian-packages.txt"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
failed=0
check() {  # NAME COMMAND...
  local name=$1; shift
  if "$@"; then echo "ok: $name"; else echo "FAILED: $name"; failed=1; fi
}

# A python3 first on PATH that is not Debian's (as pyenv's shim is on some machines).
mkdir "$scratch/path"
printf '#!/bin/sh\necho "not this python3" >&2; exit 1\n' > "$scratch/path/python3"
chmod +x "$scratch/path/python3"
commands=$(PATH="$scratch/path:$PATH" FINS_BUILD_DIR="$scratch/build" FINS_RUN_BUILD_ONLY=1 \
  FINS_NINJA_ARGS="-t commands" FINS_JOBS=1 "$root/scripts/run.sh")
cache="$scratch/build/CMakeCache.txt"
check "the release tree is configured with Debian's python3" \
  grep -q '^Python3_EXECUTABLE:[A-Z]*=/usr/bin/python3$' "$cache"
check "the finskit module is on (FINS_PYTHON)" grep -q '^FINS_PYTHON:BOOL=ON$' "$cache"
check "run.sh links the extension into build/python/finskit" \
  grep -q -- "-o python/finskit/_finskit[.a-z0-9_-]*\.so" <<<"$commands"
check "with /usr/bin/python3's headers" \
  grep -q -- "$(/usr/bin/python3 -c 'import sysconfig; print(sysconfig.get_paths()["include"])')" \
  <<<"$commands"
check "the pytest entry point is import-safe (finskit_pytest)" \
  grep -q '^finskit = finskit_pytest$' "$scratch/build/python/finskit-"*.dist-info/entry_points.txt
# Without the extension (only configured here), a pytest run with build/python on the
# path still runs, and only virtual_plc fails, saying why.
if /usr/bin/python3 -c 'import pytest' 2>/dev/null; then
  mkdir "$scratch/user"
  cat > "$scratch/user/test_user.py" <<'PY'
def test_unrelated():
    assert 1 + 1 == 2

def test_wants_the_fixture(virtual_plc):
    pass
PY
  out=$(cd "$scratch/user" && PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$scratch/build/python" \
    /usr/bin/python3 -m pytest -q -p no:cacheprovider test_user.py 2>&1 || true)
  check "an unrelated test passes without the extension" grep -q "1 passed, 1 error" <<<"$out"
  check "the fixture says why it cannot run" grep -q "finskit cannot be imported" <<<"$out"
  [[ $failed -eq 0 ]] || echo "$out"
fi
exit $failed
