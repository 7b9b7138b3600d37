#!/usr/bin/env bash
# finsd.exe's file memory under wine (docs/windows.md, docs/file-memory.md), driven by
# the host's Linux fins over FINS/UDP on 127.0.0.1: a file written to the memory card
# (22 03) lands in <data-dir>/card, reads back byte for byte (22 02), is listed (22 01)
# and deleted (22 05); a directory and a file symlink planted in the card by the host,
# both pointing outside the data directory, are neither listed, read, written through
# nor replaced, and what they point at stays untouched; a Windows device name is refused.
# Usage: windows_file_memory.sh WINDOWS_BIN_DIR HOST_BIN_DIR (WINEPREFIX and WINEDEBUG
# from ctest's environment). Every wait is for a condition, bounded in time; every
# process started is ended on exit (only those: wineserver is left to wine).
set -euo pipefail
source "$(dirname "$0")/round_trip_lib.sh"  # windows_test, free_port, wait_for
windows_test "windows file memory" "$1" "$2" "$2/fins" "$1/finsd.exe"
fins() { "$host_bin/fins" --host 127.0.0.1 --port "$port" --timeout 5 "$@"; }
refused() { ! fins "$@" >/dev/null 2>&1; }  # a non-zero exit: the PLC or the CLI said no
listed() { fins files ls "${2:-}" | tr -d '\r' | grep -q "$1"; }

mkdir -p "$work/data"
port=$(free_port)
"$wine" "$bin/finsd.exe" --bind 127.0.0.1 --port "$port" --data-dir "Z:${work}/data" \
  >"$work/finsd.log" 2>&1 &
pids+=("$!")
wait_for 120 grep -q "^listening $port" "$work/finsd.log" || fail "finsd.exe did not listen"

# Write (several 22 03 chunks), read back, list, delete.
head -c 5000 /dev/urandom >"$work/in.bin"
check fins files put "$work/in.bin" card:/HELLO.BIN
check cmp "$work/in.bin" "$work/data/card/HELLO.BIN"
check fins files get card:/HELLO.BIN "$work/out.bin"
check cmp "$work/in.bin" "$work/out.bin"
check listed HELLO.BIN
check fins files mkdir card:/SUB
check fins files put "$work/in.bin" card:/SUB/A.BIN
check listed A.BIN /SUB
check fins files rm card:/HELLO.BIN
check test ! -e "$work/data/card/HELLO.BIN"
check refused files get card:/HELLO.BIN "$work/gone.bin"

# Links planted in the card by the host, pointing outside: refused, never followed.
mkdir -p "$work/secret"
echo secret >"$work/secret/KEY.TXT"
ln -s "$work/secret" "$work/data/card/LINK"
ln -s "$work/secret/KEY.TXT" "$work/data/card/KEY.TXT"
check refused files get card:/KEY.TXT "$work/key.txt"
check test ! -s "$work/key.txt"
check refused files get card:/LINK/KEY.TXT "$work/key.txt"
check refused files put "$work/in.bin" card:/LINK/NEW.BIN
check refused files put --force "$work/in.bin" card:/KEY.TXT
check refused files rm card:/LINK/KEY.TXT
check refused files ls card:/LINK
check test "$(ls "$work/secret")" = KEY.TXT
check test "$(cat "$work/secret/KEY.TXT")" = secret
check test -L "$work/data/card/KEY.TXT"
check test "$(fins files ls | tr -d '\r' | grep -c -e LINK -e KEY.TXT)" = 0

# Names Windows treats specially never reach the host.
check refused files put "$work/in.bin" card:/CON.TXT
check refused files put "$work/in.bin" card:/COM1
check test ! -e "$work/data/card/CON.TXT"
echo "windows file memory: $passed checks passed"
