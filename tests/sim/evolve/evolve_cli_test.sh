#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# `tensegrity evolve` from the command line: the mutation schedule's options go
# together, the schedule reaches the policy's provenance and the --json summary, and
# a checkpoint refuses to continue under another schedule; the default population sizes
# and step schedule.
# Usage: evolve_cli_test.sh TENSEGRITY_BINARY
set -euo pipefail

tensegrity=$1
work=$(mktemp -d "${TMPDIR:-/tmp}/evolve_cli.XXXXXX")
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

small=(--period 1 --complexity 2 --population 4 --replace 2 --teams 4 --seed 3 --threads 1 --duration 0.5)

# An option of the schedule alone would be ignored: it is refused instead.
for lone in "--sigma-final 0.01" "--anneal-episodes 8" "--anneal-start 4"; do
  # shellcheck disable=SC2086
  if "$tensegrity" evolve "${small[@]}" $lone --episodes 8 --out "$work/p.json" --log "$work/c.csv" \
      > "$work/out" 2>&1; then
    fail "'$lone' alone was accepted"
  fi
  grep -q "requires" "$work/out" || fail "'$lone' alone: no reason given: $(cat "$work/out")"
done

sched=(--sigma 0.05 --sigma-final 0.01 --anneal-start 4 --anneal-episodes 8)
"$tensegrity" evolve "${small[@]}" "${sched[@]}" --episodes 16 --checkpoint "$work/ckpt" \
  --out "$work/p.json" --log "$work/c.csv" --json > "$work/summary.json"
/usr/bin/python3 - "$work" <<'PY' || fail "the schedule is not recorded"
import json, sys
w = sys.argv[1]
m = json.load(open(f"{w}/p.json"))["provenance"]["mutation"]
assert m == {"operator": "gaussian", "sigma_m": 0.05, "sigma_final_m": 0.01, "anneal_start_episodes": 4,
             "anneal_episodes": 8}, m
c = json.load(open(f"{w}/summary.json"))["config"]
assert (c["sigma_final_m"], c["anneal_start_episodes"], c["anneal_episodes"]) == (0.01, 4, 8), c
PY
"$tensegrity" sim --policy "$work/p.json" --duration 0.1 > /dev/null || fail "the policy does not load"

# Another schedule on --resume is another run: refused, naming the field.
if "$tensegrity" evolve "${small[@]}" --sigma 0.05 --sigma-final 0.01 --anneal-start 6 --anneal-episodes 8 \
    --episodes 24 --checkpoint "$work/ckpt" --resume --out "$work/p2.json" --log "$work/c2.csv" > "$work/out" 2>&1; then
  fail "a resume under another schedule was accepted"
fi
grep -q "anneal_start_episodes: 4 -> 6" "$work/out" || fail "the refusal does not name the field: $(cat "$work/out")"
# The author's operator: its own default step (0.03 of the 0.5 m range), recorded in
# the config, the provenance and the summary, with the gait's strut spin; another
# operator on --resume is another run.
"$tensegrity" evolve "${small[@]}" --mutation author --episodes 8 --checkpoint "$work/ack" \
  --out "$work/a.json" --log "$work/a.csv" --json > "$work/asummary.json"
/usr/bin/python3 - "$work" <<'PY' || fail "the author's operator is not recorded"
import json, sys
w = sys.argv[1]
p = json.load(open(f"{w}/a.json"))["provenance"]
assert p["mutation"]["operator"] == "author" and abs(p["mutation"]["sigma_m"] - 0.015) < 1e-12, p
assert 0 <= p["gait"]["endcaps_touched_ground"] <= 12 and p["gait"]["axial_spin_max_rad_per_s"] >= 0, p
s = json.load(open(f"{w}/asummary.json"))
assert s["config"]["mutation"] == "author" and s["gait"] == p["gait"], s
PY
if "$tensegrity" evolve "${small[@]}" --mutation gaussian --sigma 0.015 --episodes 16 --checkpoint "$work/ack" \
    --resume --out "$work/a2.json" --log "$work/a2.csv" > "$work/out" 2>&1; then
  fail "a resume under another operator was accepted"
fi
grep -q 'mutation: "author" -> "gaussian"' "$work/out" || fail "the refusal does not name the operator: $(cat "$work/out")"
# Without --population and --replace: 40 members, 20 replaced (docs/guide/evolve.md), and a
# run begun with the author's 10 and 5 is not silently continued under them.
"$tensegrity" evolve --period 1 --complexity 2 --teams 4 --seed 3 --threads 1 --duration 0.5 --episodes 4 \
  --out "$work/d.json" --log "$work/d.csv" --json > "$work/dsummary.json"
/usr/bin/python3 - "$work" <<'PY' || fail "the default sizes are not 40 and 20"
import json, sys
c = json.load(open(f"{sys.argv[1]}/dsummary.json"))["config"]
assert (c["population"], c["replace"], c["teams"]) == (40, 20, 4), c
p = json.load(open(f"{sys.argv[1]}/d.json"))["provenance"]
assert (p["population"], p["replace"], p["teams"]) == (40, 20, 4), p
PY
"$tensegrity" evolve --period 1 --complexity 2 --population 10 --replace 5 --teams 4 --seed 3 --threads 1 \
  --duration 0.5 --episodes 4 --checkpoint "$work/p10" --out "$work/p10.json" --log "$work/p10.csv" > /dev/null
if "$tensegrity" evolve --period 1 --complexity 2 --teams 4 --seed 3 --threads 1 --duration 0.5 --episodes 8 \
    --checkpoint "$work/p10" --resume --out "$work/p10.json" --log "$work/p10.csv" > "$work/out" 2>&1; then
  fail "a population-10 run was resumed under the default 40"
fi
grep -q "population: 10 -> 40" "$work/out" || fail "the refusal does not name the population: $(cat "$work/out")"
# Without a step option the Gaussian operator anneals 0.05 m to 0.02 m over episodes
# 2000-5000 (docs/guide/evolve.md); one step option makes the schedule the user's: constant.
/usr/bin/python3 - "$work" <<'PY' || fail "the default step schedule is not 0.05 -> 0.02 over 2000-5000"
import json, sys
c = json.load(open(f"{sys.argv[1]}/dsummary.json"))["config"]
got = (c["mutation"], c["sigma_m"], c["sigma_final_m"], c["anneal_start_episodes"], c["anneal_episodes"])
assert got == ("gaussian", 0.05, 0.02, 2000, 3000), c
m = json.load(open(f"{sys.argv[1]}/d.json"))["provenance"]["mutation"]
assert (m["sigma_final_m"], m["anneal_start_episodes"], m["anneal_episodes"]) == (0.02, 2000, 3000), m
PY
"$tensegrity" evolve "${small[@]}" --sigma 0.03 --episodes 4 --out "$work/s.json" --log "$work/s.csv" \
  --json > "$work/ssummary.json"
/usr/bin/python3 - "$work" <<'PY' || fail "--sigma alone does not give a constant step"
import json, sys
c = json.load(open(f"{sys.argv[1]}/ssummary.json"))["config"]
assert (c["sigma_m"], c["sigma_final_m"], c["anneal_episodes"]) == (0.03, 0.03, 0), c
PY
echo "PASS"
