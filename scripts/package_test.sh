#!/usr/bin/env bash
# Installs the finskit .debs on this machine (root: CI), exercises what they installed
# and purges them. No systemd needed: finsd is started with the unit's own ExecStart line
# (plus --port 0, so a finsd already on 9600 does not matter), as systemd would after
# creating the StateDirectory. Usage: scripts/package_test.sh build-pkg/*.deb
# Prints "package: N checks passed" last; exits non-zero on the first failure.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
debs=()
for deb in "$@"; do debs+=("$(realpath "$deb")"); done
packages=()
for deb in "${debs[@]}"; do packages+=("$(dpkg-deb -f "$deb" Package)"); done
source "$root/scripts/finsd_start.sh"
sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
passed=0
check() { echo "  ok: $1"; passed=$((passed + 1)); }
fail() { echo "FAILED: $1" >&2; exit 1; }

export DEBIAN_FRONTEND=noninteractive
for package in "${packages[@]}"; do
  if dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep "install ok installed" >/dev/null; then
    echo "$package is already installed: refusing to replace it" >&2; exit 1
  fi
done
$sudo apt-get install -y -qq --no-install-recommends "${debs[@]}" >/dev/null
socat_pids=()
cleanup() {
  if ((${#socat_pids[@]})); then kill "${socat_pids[@]}" 2>/dev/null || true; fi
  $sudo apt-get purge -y -qq "${packages[@]}" >/dev/null 2>&1 || true
}
trap cleanup EXIT
dpkg -L finskit | grep '^/usr/bin/finsd$' >/dev/null || fail "finsd installed"
check "finsd installed"
unit=$(dpkg -L finskit | grep "/systemd/system/finsd.service$")
for option in NoNewPrivileges=yes PrivateTmp=yes ProtectSystem=strict DynamicUser=yes \
    StateDirectory=finsd RuntimeDirectory=finsd SupplementaryGroups=dialout DevicePolicy=closed \
    "DeviceAllow=char-ttyS rw" "DeviceAllow=char-ttyUSB rw" "DeviceAllow=char-ttyACM rw" \
    CapabilityBoundingSet=; do
  grep -qx "$option" "$unit" || fail "unit option $option"
done
check "unit hardening options, runtime directory and serial device access"
# ProtectSystem=strict leaves only the state and runtime directories writable: the
# control socket must lie in the one, the retained memory in the other.
grep -E '^ExecStart=.* --control /run/finsd/[^ ]+' "$unit" >/dev/null || fail "control socket under /run/finsd"
grep -E '^ExecStart=.* --data-dir /var/lib/finsd( |$)' "$unit" >/dev/null || fail "data dir is the StateDirectory"
check "control socket in the RuntimeDirectory, state in the StateDirectory"
systemd-analyze verify "$unit" || fail "systemd-analyze verify $unit"
check "systemd-analyze verify finsd.service"
grep '^bind = "127.0.0.1"' /etc/finskit/finsd.toml >/dev/null || fail "config binds 127.0.0.1"
check "config binds 127.0.0.1"
dpkg-query -W -f='${Conffiles}' finskit | grep /etc/finskit/finsd.toml >/dev/null || fail "config is a conffile"
check "config is a conffile"
# fins-bridge: program, unit (not enabled by the package), example config as a conffile.
dpkg -L finskit | grep '^/usr/bin/fins-bridge$' >/dev/null || fail "fins-bridge installed"
bridge_unit=$(dpkg -L finskit | grep "/systemd/system/fins-bridge.service$")
systemd-analyze verify "$bridge_unit" || fail "systemd-analyze verify $bridge_unit"
dpkg-query -W -f='${Conffiles}' finskit | grep /etc/finskit/fins-bridge.toml >/dev/null || fail "bridge config is a conffile"
/usr/bin/fins-bridge --config /etc/finskit/fins-bridge.toml --plan | grep '^press1/fast: ' >/dev/null || fail "fins-bridge --plan of the installed config"
check "fins-bridge installed, its unit verifies, its config is a conffile and plans"

# Where systemd is PID 1 the postinst has started the service: it runs and answers on
# its control socket inside the sandbox. Elsewhere (containers, CI) that is skipped.
control=$(sed -n 's/^ExecStart=.* --control \([^ ]*\).*/\1/p' "$unit")
if [[ -d /run/systemd/system ]]; then
  systemctl is-active --quiet finsd.service || fail "finsd.service active after install"
  /usr/bin/finsd ctl --socket "$control" status >/dev/null || fail "control socket of the service"
  check "finsd.service runs under systemd and answers on $control"
else
  echo "  skipped: finsd.service under systemd (systemd is not PID 1 here)"
fi
if [[ -d /run/systemd/system ]]; then systemctl stop finsd.service; fi

# Debian policy files: DEP-5 copyright and the gzip'd changelog of this version in every
# package's doc directory; lintian finds no errors.
for deb in "${debs[@]}"; do
  package=$(dpkg-deb -f "$deb" Package)
  version=$(dpkg-deb -f "$deb" Version)
  doc=/usr/share/doc/$package
  head -n 1 "$doc/copyright" | grep -qx 'Format: https://www.debian.org/doc/packaging-manuals/copyright-format/1.0/' \
    || fail "$doc/copyright is DEP-5"
  changelog=$(dpkg-parsechangelog -l "$doc/changelog.gz" -S Version 2>/dev/null) || changelog=$(
    zcat "$doc/changelog.gz" | dpkg-parsechangelog -l - -S Version)
  [[ "$changelog" == "$version" ]] || fail "$doc/changelog.gz is at $changelog, the package at $version"
done
check "every package has a DEP-5 copyright and its version's changelog.gz"
if command -v lintian >/dev/null; then
  lintian --fail-on error --tag-display-limit 0 "${debs[@]}" || fail "lintian finds errors"
  check "lintian: no errors"
else
  echo "  skipped: lintian (not installed: scripts/deps.sh installs it)"
fi
for page in man1/fins.1.gz man8/finsd.8.gz man8/fins-bridge.8.gz; do
  for section in OPTIONS '"EXIT STATUS"' EXAMPLES '"SEE ALSO"'; do
    zcat "/usr/share/man/$page" | grep -qx "\.SH $section" || fail "man page $page has no $section"
  done
done
if command -v man >/dev/null; then
  man -w fins finsd fins-bridge >/dev/null || fail "man finds fins, finsd and fins-bridge"
fi
check "man pages fins(1), finsd(8) and fins-bridge(8) with EXIT STATUS and EXAMPLES"
# Bash completion: every verb `fins --help` lists (and every `finsd ctl` verb) completes.
completion_test() {
  local program=$1 verbs
  shift
  # shellcheck disable=SC1090
  source "/usr/share/bash-completion/completions/$program"
  verbs=$("$program" "$@" --help | awk '/^Subcommands:/ { s = 1; next } /^[^ ]/ { s = 0 } s && /^  [a-z]/ { print $1 }')
  [[ -n "$verbs" ]] || fail "$program $* --help lists verbs"
  for verb in $verbs; do
    COMP_WORDS=("$program" "$@" "${verb:0:2}")
    COMP_CWORD=$((${#COMP_WORDS[@]} - 1))
    _finskit_complete
    printf '%s\n' "${COMPREPLY[@]}" | grep -qxF -- "$verb" || fail "bash completion of '$program $* ${verb:0:2}' lacks $verb"
  done
}
completion_test fins
completion_test fins files
completion_test finsd ctl
check "bash completion offers every verb of fins, fins files and finsd ctl"
# fins-bridge has options only: each one `fins-bridge --help` lists completes.
# shellcheck disable=SC1091
source /usr/share/bash-completion/completions/fins-bridge
for option in $(fins-bridge --help | awk '/^  -/ { n = split($1, o, ","); for (i = 1; i <= n; i++) { sub(/\{.*/, "", o[i]); print o[i] } }'); do
  COMP_WORDS=(fins-bridge "${option:0:4}")
  COMP_CWORD=1
  _finskit_complete
  printf '%s\n' "${COMPREPLY[@]}" | grep -qxF -- "$option" || fail "bash completion of 'fins-bridge ${option:0:4}' lacks $option"
done
check "bash completion offers every option of fins-bridge"

# The unit's command line, run as systemd would (it creates the State- and
# RuntimeDirectory).
read -r -a exec_start <<<"$(sed -n 's/^ExecStart=//p' "$unit")"
$sudo mkdir -p /var/lib/finsd /run/finsd
finsd_start $sudo "${exec_start[@]}"
check "finsd started from the unit's ExecStart on port $finsd_port"
$sudo /usr/bin/finsd ctl --socket "$control" status | grep '"mode"' >/dev/null || fail "finsd ctl on $control"
check "finsd ctl answers on the unit's control socket $control"
fins=(/usr/bin/fins --port "$finsd_port")
"${fins[@]}" write D100 11 22 33 >/dev/null
"${fins[@]}" read D100 3 | grep "D102 *33" >/dev/null || fail "installed fins writes and reads (UDP)"
check "installed fins writes and reads (UDP)"
"${fins[@]}" --tcp read D100 1 --json | grep 11 >/dev/null || fail "installed fins over TCP"
check "installed fins over TCP"
finsd_stop
$sudo rm -rf /run/finsd
[[ -s /var/lib/finsd/finsd.state ]] || fail "state kept in the StateDirectory"
check "state kept in the StateDirectory"

# What the installed documentation says about the installed finsd holds.
[[ -s /usr/share/doc/finskit/README.md ]] || fail "README installed"
readme=/usr/share/doc/finskit/docs/finsd.md
said=$(sed -n 's/.*The cj2h file is \([0-9.]*\) MB.*/\1/p' "$readme")
size=$(stat -c %s /var/lib/finsd/finsd.state)
measured=$(awk -v s="$size" 'BEGIN { printf "%.1f", s / 1e6 }')
[[ "$said" == "$measured" ]] || fail "README says the cj2h state file is $said MB, it is $measured MB"
check "README's state file size ($said MB) is the default profile's"
readme=/usr/share/doc/finskit/docs/serial.md
# The documentation's [serial] configuration example loads on the default profile, its devices
# replaced by pseudo terminals (socat pairs).
tmp=$(mktemp -d)
awk '/^```toml$/ { b = ""; in_block = 1; next }
     in_block && /^```$/ { if (b ~ /\[serial/) { printf "%s", b; exit } in_block = 0; next }
     in_block { b = b $0 "\n" }' "$readme" >"$tmp/example.toml"
grep -q '^\[serial' "$tmp/example.toml" || fail "README's [serial] example found"
config=$(cat "$tmp/example.toml")
mapfile -t devices < <(grep -Eo '/dev/tty[A-Za-z]+[0-9]+' "$tmp/example.toml" | sort -u)
for device in "${devices[@]}"; do
  pty="$tmp/pty$((${#socat_pids[@]}))"
  socat pty,raw,echo=0,link="$pty" pty,raw,echo=0,link="$pty.peer" &
  socat_pids+=($!)
  for ((n = 0; n < 100; n++)); do
    if [[ -e "$pty" ]]; then break; fi
    sleep 0.05
  done
  config=${config//"$device"/"$pty"}
done
printf '%s\n' "$config" >"$tmp/example.toml"
finsd_start /usr/bin/finsd --config "$tmp/example.toml" || fail "README's [serial] example: $(cat "$tmp/example.toml")"
finsd_stop
kill "${socat_pids[@]}" 2>/dev/null || true
wait "${socat_pids[@]}" 2>/dev/null || true
socat_pids=()
rm -rf "$tmp"
check "README's [serial] configuration example starts finsd"
if /usr/bin/python3 -c "import finskit" 2>/dev/null; then
  /usr/bin/python3 - <<'PY'
import finskit
with finskit.VirtualPlc() as plc, finskit.Client(plc.host, plc.port) as c:
    c.write_words("D0", [1, 2])
    assert c.read_words("D0", 2) == [1, 2]
PY
  check "installed Python module"
  # The pytest plugin comes with the package (pytest11 entry point): no conftest needed.
  tests=$(mktemp -d)
  cat >"$tests/test_user.py" <<'PY'
import finskit
def test_user_code(virtual_plc):
    with finskit.Client(virtual_plc.host, virtual_plc.port, protocol="tcp") as c:
        c.write_float("D0", 2.5)
        assert c.read_float("D0") == 2.5
PY
  if /usr/bin/python3 -c "import pytest" 2>/dev/null; then
    (cd "$tests" && PYTHONDONTWRITEBYTECODE=1 /usr/bin/python3 -m pytest -q -p no:cacheprovider \
      test_user.py >/dev/null) || fail "virtual_plc fixture from the installed plugin"
    check "virtual_plc fixture from the installed plugin"
  fi
  rm -rf "$tests"
fi
pkg-config --exists fins fins-static || fail "dev files: pkg-config"
compgen -G '/usr/lib/*/cmake/fins/finsConfig.cmake' >/dev/null || fail "dev files: CMake package"
check "dev files"
tmp=$(mktemp -d)
# shellcheck disable=SC2046
g++ $(pkg-config --cflags fins) "$root/examples/typed_command.cpp" -o "$tmp/typed_command" \
  $(pkg-config --libs fins) || fail "build against the installed libfins-dev"
ldd "$tmp/typed_command" | grep -E "libfins\.so\.[0-9.]+ => (/usr)?/lib/" >/dev/null || fail "libfins0.1 used"
check "a program builds against libfins-dev and runs on libfins0.1's SONAME"
# shellcheck disable=SC2046
g++ $(pkg-config --cflags fins-static) "$root/examples/typed_command.cpp" -o "$tmp/static" \
  $(pkg-config --libs fins-static) || fail "static build against libfins-dev (fins-static)"
if ldd "$tmp/static" | grep libfins.so; then fail "pkg-config fins-static links libfins.so"; fi
rm -rf "$tmp"
check "pkg-config fins-static links libfins.a: no libfins.so loaded"

$sudo apt-get purge -y -qq "${packages[@]}" >/dev/null
trap - EXIT
for path in /usr/bin/finsd /usr/bin/fins "$unit" /etc/finskit /var/lib/finsd /usr/include/fins \
    /usr/lib/*/libfins.so* /usr/lib/python3/dist-packages/finskit; do
  if [[ -e "$path" ]]; then echo "left behind after purge: $path" >&2; exit 1; fi
done
check "purged cleanly"
echo "package: $passed checks passed"
