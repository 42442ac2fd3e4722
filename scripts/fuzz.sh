#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds the libFuzzer targets of fuzz/ (the `fuzz` preset: clang, ASan + UBSan),
# replays every seed and recorded crash, then fuzzes each target for SECONDS.
# New inputs go to a scratch copy of the corpus, never into the repository; a
# crash stops the run and leaves its input in out/fuzz/<target>/ to become a
# regression (fuzz/regressions/<target>/, docs/design/fuzzing.md).
#   scripts/fuzz.sh [SECONDS=20] [TARGET...]     (default: every target)
#   FUZZ_RUNS=N   stop each target after N executions instead (long runs)
#   FUZZ_SEED=N   libFuzzer seed (default 1: a CI run is reproducible)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
seconds="${1:-20}"
shift || true
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j "$(nproc)"
ctest --preset fuzz
bin="build/fuzz/fuzz"
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then
  mapfile -t targets < <(find "$bin" -maxdepth 1 -name 'fuzz_*' -type f -executable -printf '%f\n' | sed 's/^fuzz_//' | sort)
fi
status=0
for t in "${targets[@]}"; do
  work="out/fuzz/$t"
  rm -rf "$work" && mkdir -p "$work/corpus"
  cp -r "fuzz/corpus/$t/." "$work/corpus/"
  args=(-seed="${FUZZ_SEED:-1}" -max_len=8192 -print_final_stats=1 -artifact_prefix="$work/")
  [[ -f "fuzz/dict/$t.dict" ]] && args+=(-dict="fuzz/dict/$t.dict")
  if [[ -n "${FUZZ_RUNS:-}" ]]; then args+=(-runs="$FUZZ_RUNS"); else args+=(-max_total_time="$seconds"); fi
  if [[ -n "${FUZZ_RUNS:-}" ]]; then budget="$FUZZ_RUNS runs"; else budget="$seconds s"; fi
  echo "fuzz: $t ($budget)"
  if ! TENSEGRITY_SOURCE_DIR="$root" "$bin/fuzz_$t" "${args[@]}" "$work/corpus" >"$work/log.txt" 2>&1; then
    echo "fuzz: $t FAILED; input and log in $work/" >&2
    tail -n 40 "$work/log.txt" >&2
    status=1
  fi
  grep -E '^stat::(number_of_executed_units|average_exec_per_sec|new_units_added)' "$work/log.txt" | sed "s/^/fuzz: $t /" || true
done
exit $status
