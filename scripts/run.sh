#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The README's main job: build, take the shipped rolling policy (or evolve one with
# --evolve), simulate it in-process, then roll it with 12 real end-cap firmware
# processes against the ODE model (HIL, lockstep), and report: distance, per end
# cap summary, and a plot (out/hil-run.png).
# It ends by printing the command that replays the run in a browser (tensegrity view).
#   scripts/run.sh [--evolve [--seed N]] [--duration S]
# The robot is the default, the paper's simulated SUPERball (robots/superball-paper.json);
# --evolve learns with tensegrity evolve's defaults: 40 members per cable population (the
# author's is 10) and a 0.05 m step annealed to 0.02 m over episodes 2000-5000. With them
# 10 of seeds 1-10 learned a 33-35 m gait in 5000 episodes (docs/reproduction.md, "The cables");
# seed 1 learns 33.7 m, the shipped policy to the last digit
# (tests/sim/shipped_policy_test.cpp holds the shipped file to this seed and these settings).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
evolve=0
seed=1
duration=60
while [[ $# -gt 0 ]]; do
  case "$1" in
    --evolve) evolve=1 ;;
    --duration) duration="${2:?run: --duration needs seconds}"; shift ;;
    --seed) seed="${2:?run: --seed needs a number}"; shift ;;
    -h|--help) sed -n '3,14p' "$0"; exit 0 ;;
    *) echo "run: unknown argument $1 (try --help)" >&2; exit 2 ;;
  esac
  shift
done
# Checked before the build, not after minutes of it.
[[ $seed =~ ^[0-9]+$ ]] || { echo "run: --seed must be a whole number, not '$seed'" >&2; exit 2; }

scripts/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)" --target tensegrity endcap >/dev/null
bin=build/release
tensegrity="$bin/cli/tensegrity"
mkdir -p out

policy=policies/superball-paper-t4-n5.json
if [[ $evolve -eq 1 ]]; then
  policy=out/evolved.json
  echo "== evolving a policy (t = 4 s, n = 5, historical average, population 40, step 0.05 -> 0.02 m, 5000 episodes, seed $seed)"
  # The checkpoint is per robot, seed and schedule: --resume must not continue another
  # seed's run, nor one begun on another robot (its robot hash differs: it would be refused).
  "$tensegrity" evolve --robot robots/superball-paper.json --period 4 --complexity 5 --method historical --episodes 5000 \
    --population 40 --replace 20 --seed "$seed" --checkpoint "out/evolve-checkpoint-paper-p40-anneal-s$seed" --resume \
    --out "$policy" --log out/evolve-curve.csv
fi

echo "== in-process simulation of $policy, ${duration} s"
"$tensegrity" sim --policy "$policy" --duration "$duration"

echo "== HIL: 12 endcap processes over CAN-over-UDP against the ODE model, lockstep, ${duration} s"
"$tensegrity" hil --policy "$policy" --duration "$duration" --endcap "$bin/firmware/endcap/endcap" \
  --record out/hil-run.csv
# Debian's interpreter: it is the one python3-matplotlib installs into.
/usr/bin/python3 tools/plot_run.py out/hil-run.csv out/hil-run.png
robot=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["robot"])' "$policy")
echo
echo "== watch the run in a browser (3D replay with plots; docs/guide/view.md):"
echo "   $tensegrity view out/hil-run.csv --robot robots/$robot.json    # then open http://127.0.0.1:8080/"
