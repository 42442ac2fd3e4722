#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds everything and runs every test: the host build (ctest, which includes the
# SocketCAN tests in a VM with a real kernel), then the firmware cross-built for the
# end caps' ARMv7 boards with its tests under qemu-arm, and the libFuzzer targets
# (scripts/fuzz.sh). The README's test command.
#   TENSEGRITY_TEST_PRESET=asan  host preset (default: default)
#   TENSEGRITY_CROSS=none        skip the cross build (default: armhf; also aarch64)
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
scripts/setup.sh
scripts/setup-cross.sh
preset="${TENSEGRITY_TEST_PRESET:-default}"
start=$(date +%s)
# Every C++ file as .clang-format says (seconds; before the build, so it fails first).
scripts/check_format.sh
cmake --preset "$preset" >/dev/null
cmake --build --preset "$preset" -j "$(nproc)"
# No source file over 400 lines, no function over 80 (scripts/size-exceptions.txt).
/usr/bin/python3 scripts/check_size.py -p "build/$preset" --self-test
# Which room may include which (scripts/layers.json: each room includes only the
# rooms its target links; core the C++ standard library only).
/usr/bin/python3 scripts/check_layers.py --self-test
# A host build without DDS (TENSEGRITY_WITH_DDS=OFF: no msgs, node, ground tools or
# view) must configure, and its `endcap` program (the firmware for a board without
# the Wi-Fi link: tables from --policy and storage) must build: about 2 minutes; the
# rest of that build would double CI's time for code the default build compiles.
nodds_start=$(date +%s)
cmake -S . -B build/nodds -G Ninja -DTENSEGRITY_WITH_DDS=OFF -DTENSEGRITY_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build/nodds -j "$(nproc)" --target endcap
build/nodds/firmware/endcap/endcap --help >/dev/null
echo "test: the DDS-off endcap took $(( $(date +%s) - nodds_start )) s"
ctest --preset "$preset"
echo "test: host $preset build and tests took $(( $(date +%s) - start )) s"
# Every decoder of outside input under libFuzzer: corpora and recorded crashes
# replayed, then 5000 seeded executions per target (docs/design/fuzzing.md). A count, not
# a time: with the seed fixed the run is the same on every machine, so CI cannot
# go red on an input this checkout was never shown.
fuzz_start=$(date +%s)
FUZZ_RUNS=5000 scripts/fuzz.sh
echo "test: fuzzing took $(( $(date +%s) - fuzz_start )) s"
# ASan + UBSan on the firmware's unit tests and the host's readers of outside input,
# TSan on the loop's mailbox and the HIL's hub (the subset that fits CI's time;
# scripts/sanitize.sh asan tsan runs the wider sets).
san_start=$(date +%s)
scripts/sanitize.sh ci
echo "test: sanitizers took $(( $(date +%s) - san_start )) s"
for arch in ${TENSEGRITY_CROSS:-armhf}; do
  [[ "$arch" == none ]] && continue
  JOBS="$(nproc)" scripts/cross-test.sh "$arch"
done
