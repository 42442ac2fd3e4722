#!/bin/sh
# SPDX-License-Identifier: Apache-2.0
# `tensegrity robustness` on a short episode of the shipped policy: the JSON names every
# case with its distance and retention and the worst case; the table prints them; a
# bad set is refused naming the field.
set -eu
cli="$1"
src="${TENSEGRITY_SOURCE_DIR:?}"
policy="$src/policies/superball-paper-t4-n5.json"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

cat > "$out/set.json" <<'JSON'
{"format": "tensegrity-perturbation-set/1",
 "cases": [{"name": "slow motors", "motor_speed_scale": 0.8},
           {"name": "late", "actuation_delay_s": 0.05},
           {"name": "bullet", "engine": "bullet"},
           {"name": "bumps", "rough": {"bump_height_m": 0.03, "bump_spacing_m": 0.5, "seed": 2}}]}
JSON
"$cli" robustness "$policy" --set "$out/set.json" --duration 4 --threads 2 --json > "$out/r.json"
/usr/bin/python3 - "$out/r.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["format"] == "tensegrity-robustness/1", r["format"]
assert r["duration_s"] == 4
nominal = r["nominal"]["distance_m"]
assert nominal > 0.1, nominal
names = [c["name"] for c in r["cases"]]
assert names == ["slow motors", "late", "bullet", "bumps"], names
for c in r["cases"]:
    assert "error" not in c, c
    assert abs(c["retention"] - c["distance_m"] / nominal) < 1e-12, c
    assert c["robot_hash"] != r["robot_hash"], c["name"]
worst = min(r["cases"], key=lambda c: c["retention"])
assert r["worst"]["name"] == worst["name"], (r["worst"], worst["name"])
PY
"$cli" robustness "$policy" --set "$out/set.json" --duration 2 --threads 1 > "$out/table.txt"
grep -q "^  nominal" "$out/table.txt" || { echo "FAIL: no nominal row"; cat "$out/table.txt"; exit 1; }
grep -q "^worst: " "$out/table.txt" || { echo "FAIL: no worst line"; cat "$out/table.txt"; exit 1; }

echo '{"format": "tensegrity-perturbation-set/1", "cases": [{"name": "x", "friction_scale": -1}]}' > "$out/bad.json"
if "$cli" robustness "$policy" --set "$out/bad.json" --duration 1 2> "$out/err.txt"; then
  echo "FAIL: a bad set was accepted"; exit 1
fi
grep -q "cases\[0\].friction_scale" "$out/err.txt" || { echo "FAIL: error names no field"; cat "$out/err.txt"; exit 1; }
echo "robustness CLI: ok"
