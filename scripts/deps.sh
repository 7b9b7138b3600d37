#!/usr/bin/env bash
# Installs the Debian packages of a list that are missing. Usage: scripts/deps.sh [arm64]
#   (none)  scripts/debian-packages.txt: what finskit builds and tests with on the host
#   arm64   scripts/debian-packages-arm64.txt: the cross build's (adds Debian's arm64
#           architecture to dpkg first when a package names it)
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
list="$here/debian-packages.txt"
[[ $# -gt 0 ]] && list="$here/debian-packages-$1.txt"
[[ -f "$list" ]] || { echo "deps: no package list $list" >&2; exit 2; }
missing=()
while read -r pkg; do
  [[ -z "$pkg" || "$pkg" == \#* ]] && continue
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done < "$list"
if ((${#missing[@]} == 0)); then
  exit 0
fi
echo "deps: installing ${missing[*]}"
sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
for pkg in "${missing[@]}"; do
  if [[ "$pkg" == *:* ]] && ! dpkg --print-foreign-architectures | grep -qx "${pkg##*:}"; then
    $sudo dpkg --add-architecture "${pkg##*:}"
  fi
done
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
