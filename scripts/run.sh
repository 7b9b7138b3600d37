#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to a running virtual PLC: installs what is
# missing, builds (Release) and starts finsd, which listens on 127.0.0.1 port 9600 with the
# CJ2H profile unless told otherwise (Ctrl-C stops it).
# Also builds the finskit Python module in build/python (PYTHONPATH=build/python python3
# -c 'import finskit', Debian's /usr/bin/python3) when pybind11 and python3-dev are there.
# finsd's control channel is at its default place, so `finsd ctl status` reaches it.
# Extra arguments go to finsd, e.g. scripts/run.sh --port 9601 --node 10
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/deps.sh"
"$root/scripts/build.sh" release finsd fins fins-bridge fins_load fins_micro
if grep -q '^FINS_PYTHON:BOOL=ON' "${FINS_BUILD_DIR:-$root/build}/CMakeCache.txt"; then
  "$root/scripts/build.sh" release finskit_python
fi
if [[ -n "${FINS_RUN_BUILD_ONLY:-}" ]]; then exit 0; fi  # tests/scripts/run_sh_test.sh
exec "${FINS_BUILD_DIR:-$root/build}/bin/finsd" "$@"  # defaults: 127.0.0.1, port 9600, profile CJ2H
