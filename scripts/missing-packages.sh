#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Prints, one per line, the packages of a list file (one name per line, '#'
# comments) that are not installed. A plain name means this machine's architecture
# (or all); name:arch means that architecture: with multiarch, another
# architecture's copy (libfastrtps-dev:armhf) does not count for the native one.
# Shared by setup.sh and setup-cross.sh.
set -euo pipefail
native="$(dpkg --print-architecture)"
installed() {
  local name="${1%%:*}" arch="$native" status
  [[ "$1" == *:* ]] && arch="${1##*:}"
  status="$(dpkg-query -W -f='${Status} ${Architecture}\n' "$name:$arch" 2>/dev/null || true
            dpkg-query -W -f='${Status} ${Architecture}\n' "$name" 2>/dev/null || true)"
  grep -qE "^install ok installed ($arch|all)$" <<<"$status"
}
sed -e 's/#.*//' -e 's/[[:space:]]//g' "$1" | grep -v '^$' | while read -r pkg; do
  installed "$pkg" || echo "$pkg"
done
