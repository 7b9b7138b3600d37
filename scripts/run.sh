#!/usr/bin/env bash
# One command from a fresh Debian 12 machine to a running virtual PLC: installs what is
# missing, builds (Release) and starts finsd, which listens on 127.0.0.1 port 9600 with the
# CJ2H profile unless told otherwise (Ctrl-C stops it).
# Extra arguments go to finsd, e.g. scripts/run.sh --port 9601 --node 10
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/deps.sh"
"$root/scripts/build.sh" release finsd fins fins-bridge fins_load fins_micro
exec "$root/build/bin/finsd" "$@"  # defaults: 127.0.0.1, port 9600, profile CJ2H
