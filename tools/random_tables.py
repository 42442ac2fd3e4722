#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Play N uniformly random policy tables on one robot and summarise what they do.

The first generation of the coevolution is made of such tables, so how far they
roll, how often they break the tension limit and how the struts move in them says
what landscape the learner starts on. Each table is played by `tensegrity sim
--policy ... --json` (the firmware's control core on the ODE model). Tables are
drawn from --seed, so two robots (or two --set variants) get the same tables.

Output (OUT/tables.csv, OUT/summary.json, and a readable summary on stdout): per
table the distance, feasibility, tensions, end caps on the ground, strut spin, the
closest two struts came and for how long two overlapped.

  tools/random_tables.py --out out/tables/axis --robot robots/superball.json --tables 120
  tools/random_tables.py --out out/tables/rods --robot robots/superball.json \\
      --set strut.rod_contact=true --tables 120
"""
import argparse
import concurrent.futures
import csv
import json
import pathlib
import random
import statistics
import sys

from tensegrity_tools import program, robot_file

FIELDS = ["table", "distance_m", "feasible", "max_tension_n", "mean_tension_n", "endcaps_touched_ground",
          "axial_spin_rms_rad_per_s", "min_strut_gap_m", "strut_overlap_s"]


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True, help="output directory")
    program.add_option(p)
    p.add_argument("--robot", default=str(program.ROOT / "robots/superball-paper.json"),
                   help="robot description (default: the default robot, the paper's simulated SUPERball)")
    robot_file.add_set_option(p)
    p.add_argument("--tables", type=int, default=120, help="random tables (default: %(default)s)")
    p.add_argument("--seed", type=int, default=1, help="seed of the tables (default: %(default)s)")
    p.add_argument("--period", type=float, default=4.0, help="policy period, s (default: %(default)s)")
    p.add_argument("--complexity", type=int, default=5, help="values per cable (default: %(default)s)")
    p.add_argument("--start", default="settled", choices=["settled", "drop"], help="episode start")
    p.add_argument("--jobs", type=int, default=2, help="episodes at a time (default: %(default)s)")
    return p.parse_args()


def table(rng, robot_doc, complexity):
    lo, hi = robot_doc["cable"]["min_rest_length_m"], robot_doc["cable"]["max_rest_length_m"]
    return [{"cable": i, "owner": c["owner"], "rest_lengths_m": [rng.uniform(lo, hi) for _ in range(complexity)]}
            for i, c in enumerate(robot_doc["cables"])]


def quantile(values, q):
    return statistics.quantiles(values, n=100, method="inclusive")[q - 1] if len(values) > 1 else values[0]


def summarise(rows):
    d = [r["distance_m"] if r["feasible"] else 0.0 for r in rows]
    overlapping = [r for r in rows if r["min_strut_gap_m"] < 0.0]
    return {
        "tables": len(rows),
        "distance_mean_m": statistics.fmean(d),
        "distance_median_m": statistics.median(d),
        "distance_p90_m": quantile(d, 90),
        "distance_max_m": max(d),
        "infeasible": sum(1 for r in rows if not r["feasible"]),
        "tables_with_overlapping_struts": len(overlapping),
        "overlap_s_median_of_those": statistics.median([r["strut_overlap_s"] for r in overlapping]) if overlapping else 0.0,
        "min_strut_gap_m_median": statistics.median(r["min_strut_gap_m"] for r in rows),
        "endcaps_touched_median": statistics.median(r["endcaps_touched_ground"] for r in rows),
    }


def main():
    args = parse_args()
    out = pathlib.Path(args.out)
    (out / "tables").mkdir(parents=True, exist_ok=True)
    args.tensegrity = program.find(args.tensegrity)
    robot = robot_file.write_robot(args.robot, args.set, out)
    robot_doc = json.loads(robot.read_text())
    rng = random.Random(args.seed)
    paths = []
    for i in range(args.tables):
        policy = {"format": "tensegrity-policy/1", "robot": robot_doc["name"], "period_s": args.period,
                  "complexity": args.complexity, "cables": table(rng, robot_doc, args.complexity)}
        path = out / "tables" / f"t{i:04d}.json"
        path.write_text(json.dumps(policy))
        paths.append(path)
    rows = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for i, result in enumerate(pool.map(lambda p: program.sim(args.tensegrity, p, robot, ["--start", args.start]), paths)):
            rows.append({"table": i, **{k: result[k] for k in FIELDS[1:]}})
            if (i + 1) % 20 == 0:
                print(f"  {i + 1}/{args.tables} tables played", file=sys.stderr, flush=True)
    with open(out / "tables.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    summary = {"robot": str(args.robot), "set": args.set, "seed": args.seed, "start": args.start, **summarise(rows)}
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    print(json.dumps(summary, indent=2))


if __name__ == "__main__":
    main()
