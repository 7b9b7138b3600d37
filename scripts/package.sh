#!/usr/bin/env bash
# Builds the installable finskit (Release tree build-pkg, prefix /usr): libfins, finsd,
# fins, the examples and the finskit Python module, then the Debian package with CPack.
# Usage: scripts/package.sh            build + the .debs in build-pkg: finskit, libfins0.1,
#                                      libfins-dev, python3-finskit
#        scripts/package.sh --install-test
#            also installs the .deb with apt, starts finsd from the installed files with
#            the unit's ExecStart line (no systemd needed), reads and writes through the
#            installed fins, and purges the package (needs root: CI).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build-pkg"
jobs=${FINS_JOBS:-$(nproc)}
# No tests, benchmarks or in-tree examples: the ASan tree builds those, consumers.sh the
# examples against the install.
args=(-DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr -DFINS_TESTS=OFF -DFINS_BENCH=OFF
  -DFINS_EXAMPLES=OFF -DFINS_MAN=ON)
# The .deb's Python module is for Debian's own interpreter, whatever else is on PATH.
if [[ -x /usr/bin/python3 ]]; then args+=(-DPython3_EXECUTABLE=/usr/bin/python3); fi
source "$root/scripts/ccache.sh"
args+=("${fins_ccache_args[@]}")
cmake -S "$root" -B "$build" -G Ninja "${args[@]}" >/dev/null
ninja -C "$build" -j "$jobs"
rm -f "$build"/*.deb
(cd "$build" && cpack -G DEB >/dev/null)
debs=("$build"/*.deb)
printf 'package: %s\n' "${debs[@]}"
[[ "${1:-}" == --install-test ]] || exit 0
"$root/scripts/package_test.sh" "${debs[@]}"
