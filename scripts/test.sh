#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds everything and runs every test: the host build (ctest, which includes the
# SocketCAN tests in a VM with a real kernel), then the firmware cross-built for the
# end caps' ARMv7 boards with its tests under qemu-arm. The README's test command.
#   TENSEGRITY_TEST_PRESET=asan  host preset (default: default)
#   TENSEGRITY_CROSS=none        skip the cross build (default: armhf; also aarch64)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
scripts/setup.sh
scripts/setup-cross.sh
preset="${TENSEGRITY_TEST_PRESET:-default}"
start=$(date +%s)
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" -j "$(nproc)"
# No source file over 400 lines, no function over 80 (scripts/size-exceptions.txt).
python3 scripts/check_size.py -p "build/$preset" --self-test
ctest --preset "$preset"
echo "test: host $preset build and tests took $(( $(date +%s) - start )) s"
for arch in ${TENSEGRITY_CROSS:-armhf}; do
  [[ "$arch" == none ]] && continue
  JOBS="$(nproc)" scripts/cross-test.sh "$arch"
done
