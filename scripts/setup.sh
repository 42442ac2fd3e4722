#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs every Debian package the project needs (scripts/debian-packages.txt).
# Idempotent and silent when everything is already there.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

# DDS on one host (the HIL: 13 participants, 1,200 telemetry samples a second)
# needs socket buffers above Linux's default 208 KiB cap; msgs/qos_profiles.xml
# asks for 4 MiB and the kernel silently caps it (docs/dds.md "Socket buffers").
want=4194304
for key in rmem_max wmem_max; do
  have=$(cat "/proc/sys/net/core/$key" 2>/dev/null || echo "$want")
  if (( have < want )); then
    if [[ $(id -u) -eq 0 ]] && sysctl -qw "net.core.$key=$want" 2>/dev/null; then
      echo "setup: net.core.$key $have -> $want (DDS socket buffers)"
    else
      echo "setup: net.core.$key is $have; run 'sysctl -w net.core.$key=$want' as root for a reliable HIL" >&2
    fi
  fi
done

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
