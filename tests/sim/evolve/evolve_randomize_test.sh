#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `tensegrity evolve --randomize` from the command line: the same seed gives the same
# learning curve, byte for byte; the checkpoint records the randomization and refuses
# another K; a bad file is refused naming the field; --mpi refuses it.
# Usage: evolve_randomize_test.sh TENSEGRITY_BINARY
set -euo pipefail

tensegrity=$1
work=$(mktemp -d "${TMPDIR:-/tmp}/evolve_randomize.XXXXXX")
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

file="$TENSEGRITY_SOURCE_DIR/docs/design/randomization.json"
base=(--period 1 --complexity 2 --population 4 --replace 2 --teams 4 --seed 3 --duration 0.5 --randomize-score q25)
small=("${base[@]}" --randomize "$file" --randomize-k 2)

"$tensegrity" evolve "${small[@]}" --threads 2 --episodes 8 --out "$work/a.json" --log "$work/a.csv" > /dev/null
"$tensegrity" evolve "${small[@]}" --threads 1 --episodes 8 --out "$work/b.json" --log "$work/b.csv" > /dev/null
cmp -s "$work/a.csv" "$work/b.csv" || fail "the same seed gave another curve"

"$tensegrity" evolve "${small[@]}" --episodes 4 --checkpoint "$work/ck" --out "$work/c.json" --log "$work/c.csv" \
  > /dev/null
grep -q '"randomization"' "$work/ck/checkpoint.json" || fail "the checkpoint does not record the randomization"
set +e
"$tensegrity" evolve "${base[@]}" --randomize "$file" --randomize-k 3 --episodes 8 --checkpoint "$work/ck" --resume \
  --out "$work/c.json" --log "$work/c.csv" > "$work/out" 2>&1
code=$?
set -e
[[ $code == 3 ]] || fail "resume with another K: exit $code, expected 3: $(cat "$work/out")"
grep -q "randomization" "$work/out" || fail "resume with another K: the difference is not named"
"$tensegrity" evolve "${small[@]}" --episodes 8 --checkpoint "$work/ck" --resume --out "$work/c.json" \
  --log "$work/c.csv" > /dev/null
cmp -s "$work/a.csv" "$work/c.csv" || fail "the resumed run differs from the uninterrupted one"

echo '{"format": "tensegrity-randomization/1", "ranges": {"friction_scale": {"min": 1.5, "max": 1.2}}}' \
  > "$work/bad.json"
for extra in "--randomize $work/bad.json" "--randomize $file --mpi"; do
  set +e
  # shellcheck disable=SC2086
  "$tensegrity" evolve "${base[@]}" $extra --episodes 4 --out "$work/d.json" --log "$work/d.csv" > "$work/out" 2>&1
  code=$?
  set -e
  [[ $code == 2 ]] || fail "'$extra': exit $code, expected 2: $(cat "$work/out")"
  [[ $extra == *--mpi ]] || grep -q "ranges.friction_scale.max: must be at least min" "$work/out" ||
    fail "the bad file's field is not named: $(cat "$work/out")"
done
echo "PASS"
