#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Runs test_socketcan_vcan directly where the host kernel has a vcan interface
# (TENSEGRITY_VCAN_IF, default vcan0); exits 77 (ctest's SKIP_RETURN_CODE) when it
# has none. Usage: tests/vm/run-vcan-host.sh [EMULATOR...] TEST_BINARY [ARGS...]
# Create one with: modprobe vcan; ip link add dev vcan0 type vcan; ip link set up vcan0
set -euo pipefail
iface="${TENSEGRITY_VCAN_IF:-vcan0}"
if [[ ! -e "/sys/class/net/$iface" ]]; then
  echo "run-vcan-host: SKIP: no interface $iface on this host" >&2
  exit 77
fi
if [[ "$(cat "/sys/class/net/$iface/type" 2>/dev/null)" != 280 ]]; then  # ARPHRD_CAN
  echo "run-vcan-host: SKIP: $iface is not a CAN interface" >&2
  exit 77
fi
export TENSEGRITY_VCAN_IF="$iface"
exec "$@"
