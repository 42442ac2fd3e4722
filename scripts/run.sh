#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The README's main job: build, then play the shipped rolling policy on the
# SUPERball model and print the summary (extra arguments go to `tensegrity sim`).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)" --target tensegrity >/dev/null
tensegrity=build/release/cli/tensegrity
policy=policies/superball-t4-n5.json
if [[ -f "$policy" ]]; then
  exec "$tensegrity" sim --policy "$policy" "$@"
fi
echo "run: no shipped policy yet ($policy); playing the benchmark policy" >&2
exec "$tensegrity" sim --benchmark-policy "$@"
