#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Cross-builds the firmware and its unit tests for ARCH and runs the tests under
# qemu-user: scripts/setup-cross.sh, then the CMake preset ARCH (configure, build,
# ctest). Usage: scripts/cross-test.sh [--fresh] armhf|aarch64 [ctest args...]
#   --fresh   remove build/ARCH first (a cold build)
#   JOBS=N    build parallelism (default 2)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
fresh=0
if [[ "${1:-}" == "--fresh" ]]; then fresh=1; shift; fi
arch="${1:-}"
case "$arch" in
  armhf|arm|arm-linux-gnueabihf) preset=armhf ;;
  aarch64|arm64|aarch64-linux-gnu) preset=aarch64 ;;
  *) echo "usage: $0 [--fresh] armhf|aarch64 [ctest args...]" >&2; exit 2 ;;
esac
shift

cd "$root"
"$root/scripts/setup-cross.sh"
start=$(date +%s)
[[ $fresh -eq 1 ]] && rm -rf "build/$preset"
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" --parallel "${JOBS:-2}"
built=$(date +%s)
status=0
ctest --preset "$preset" "$@" || status=$?
done_=$(date +%s)
echo "cross-test $preset: build $((built - start)) s, test $((done_ - built)) s, total $((done_ - start)) s"
exit $status
