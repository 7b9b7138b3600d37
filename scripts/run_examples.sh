#!/usr/bin/env bash
# Runs the example programs against a finsd on port 0 (UDP, and read_write over TCP).
# Usage: scripts/run_examples.sh FINSD EXAMPLE... (ctest: examples.against_finsd)
set -euo pipefail
source "$(dirname "$0")/finsd_start.sh"
finsd=$1
shift
finsd_start "$finsd" --bind 127.0.0.1
trap finsd_stop EXIT
for example in "$@"; do
  "$example" 127.0.0.1 "$finsd_port"
done
"$1" 127.0.0.1 "$finsd_port" --tcp
