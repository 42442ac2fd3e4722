#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs what cross builds and the SocketCAN VM test need
# (scripts/debian-packages-cross.txt): adds the armhf and arm64 dpkg architectures
# first. Idempotent and silent when everything is already there.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
list="${1:-$here/debian-packages-cross.txt}"
mapfile -t missing < <("$here/missing-packages.sh" "$list")
[[ ${#missing[@]} -eq 0 ]] && exit 0

if [[ $(id -u) -ne 0 ]]; then
  echo "setup-cross: missing packages: ${missing[*]} (run as root, or install them with apt-get)" >&2
  exit 1
fi
# Foreign-architecture packages (name:armhf, name:arm64) need their architecture.
foreign=0
for pkg in "${missing[@]}"; do
  if [[ "$pkg" == *:armhf || "$pkg" == *:arm64 ]]; then foreign=1; fi
done
if [[ $foreign -eq 1 ]]; then
  for arch in armhf arm64; do
    dpkg --print-foreign-architectures | grep -qx "$arch" || dpkg --add-architecture "$arch"
  done
fi
echo "setup-cross: installing ${#missing[@]} Debian package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
# A partial index failure (a mirror mid-sync for one architecture) is not fatal:
# apt uses what it has, and the version pinning below copes with the gap.
apt-get update -qq || echo "setup-cross: apt-get update reported errors; going on" >&2

# Multi-Arch: same packages must have the very same version for every architecture.
# The native libssl may come from bookworm-security while a foreign architecture's
# index lags behind, and apt then reports held packages: install the newest version
# that every architecture offers, for all of them together.
archs=(amd64 armhf arm64)
pins=()
twins=()
if [[ $foreign -eq 1 ]]; then twins=(libssl3 libssl-dev); fi
for twin in ${twins[@]+"${twins[@]}"}; do
  common=""
  for arch in "${archs[@]}"; do
    versions="$(apt-cache madison "$twin:$arch" 2>/dev/null | awk -F'|' '{gsub(/ /,"",$2); print $2}' | sort -u)"
    if [[ -z "$common" ]]; then common="$versions"; else common="$(comm -12 <(echo "$common") <(echo "$versions"))"; fi
  done
  best="$(echo "$common" | sed '/^$/d' | sort -V | tail -n1)"
  [[ -n "$best" ]] || continue
  for arch in "${archs[@]}"; do pins+=("$twin:$arch=$best"); done
done
apt-get install -y -qq --no-install-recommends --allow-downgrades ${pins[@]+"${pins[@]}"} "${missing[@]}" >/dev/null
echo "setup-cross: done"
