#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs every Debian package the project needs (scripts/debian-packages.txt).
# Idempotent and silent when everything is already there.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
mapfile -t missing < <("$here/missing-packages.sh" "$here/debian-packages.txt")
[[ ${#missing[@]} -eq 0 ]] && exit 0

if [[ $(id -u) -ne 0 ]]; then
  echo "setup: missing packages: ${missing[*]} (run as root, or install them with apt-get)" >&2
  exit 1
fi
echo "setup: installing ${#missing[@]} Debian package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
# A mirror caught mid-sync for one index (seen for a foreign architecture) is not
# fatal: apt uses what it has; a real failure shows in the install below.
apt-get update -qq || echo "setup: apt-get update reported errors; going on" >&2
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
