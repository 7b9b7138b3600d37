#!/usr/bin/env bash
# Builds the installable finskit (Release tree build-pkg, prefix /usr): libfins, finsd,
# fins, the examples and the finskit Python module, then the Debian package with CPack.
# Usage: scripts/package.sh            build + the .debs in build-pkg: finskit, libfins0.1,
#                                      libfins-dev, python3-finskit
#        scripts/package.sh --install-test
#            also installs the .deb with apt, starts finsd from the installed files with
#            the unit's ExecStart line (no systemd needed), reads and writes through the
#            installed fins, and purges the package (needs root: CI).
#        scripts/package.sh arm64
#            the arm64 .debs (finskit, libfins0.1, libfins-dev; no python3-finskit: the
#            module is built for the host's interpreter) from the cross tree build-arm64
#            (scripts/build.sh arm64, docs/platforms.md), man pages made under qemu-user.
#        scripts/package.sh windows
#            finskit-VERSION-windows-x86_64.zip from the cross tree build-windows
#            (scripts/build.sh windows, docs/windows.md).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build-pkg"
jobs=${FINS_JOBS:-$(nproc)}
if [[ "${1:-}" == windows ]]; then
  # The Windows zip (docs/windows.md) from the cross tree build-windows.
  "$root/scripts/build.sh" windows all
  rm -f "$root"/build-windows/finskit-*-windows-x86_64.zip
  (cd "$root/build-windows" && cpack -G ZIP >/dev/null)
  printf 'package: %s\n' "$root"/build-windows/finskit-*-windows-x86_64.zip
  exit 0
fi
if [[ "${1:-}" == arm64 ]]; then
  # One arm64 tree for the tests and the packages: everything it builds, then CPack.
  "$root/scripts/build.sh" arm64 all
  rm -f "$root"/build-arm64/*.deb
  (cd "$root/build-arm64" && cpack -G DEB >/dev/null)
  printf 'package: %s\n' "$root"/build-arm64/*.deb
  exit 0
fi
# No tests, benchmarks or in-tree examples: the ASan tree builds those, consumers.sh the
# examples against the install.
source "$root/scripts/release_opt.sh"
args=(-DCMAKE_BUILD_TYPE=Release "${fins_release_opt[@]}" -DCMAKE_INSTALL_PREFIX=/usr -DFINS_TESTS=OFF -DFINS_BENCH=OFF
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
