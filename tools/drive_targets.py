#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Measures `tensegrity drive --sim` against its targets and prints the table
(docs/design/steering.md, "Driving"):

- goals 20 m from the settled start every 30 degrees, each with three noise seeds:
  reached within 1.5 m in at most 90 s of physics, and the speed made good
  (20 m over the time to the goal, m/min, target 25);
- the 10 m square and back to the start, within 1.5 m each, in at most 240 s;
- no end cap faulted and no cable above the hard limit; cut-off steps counted.

  tools/drive_targets.py [--tensegrity BIN] [--seeds 1,2,3] [--jobs 2] [--headings 0,30,...] [--no-square]
                          [--gaits SET]
"""
import argparse
import concurrent.futures
import json
import math
import subprocess
import sys

from tensegrity_tools import program


def drive(binary, waypoints, seed, time_limit, gaits):
    cmd = [binary, "drive", "--sim", "--json", "--seed", str(seed), "--time-limit", str(time_limit)]
    if gaits:
        cmd += ["--gaits", gaits]
    for x, y in waypoints:
        cmd += ["--to", f"{x:.3f},{y:.3f}"]
    # Exit 1 is a course not completed: its JSON still says how far it got.
    out = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if out.returncode not in (0, 1) or not out.stdout.strip():
        raise SystemExit(f"{' '.join(cmd)} failed ({out.returncode}): {out.stderr.strip()}")
    return json.loads(out.stdout)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    program.add_option(parser)
    parser.add_argument("--seeds", default="1,2,3")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--headings", default=",".join(str(h) for h in range(0, 360, 30)))
    parser.add_argument("--no-square", action="store_true")
    parser.add_argument("--gaits", help="gait set file passed to drive (default: drive's own)")
    args = parser.parse_args()
    binary = program.find(args.tensegrity)
    seeds = [int(s) for s in args.seeds.split(",")]
    headings = [float(h) for h in args.headings.split(",")]
    jobs = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        for h in headings:
            goal = (20.0 * math.cos(math.radians(h)), 20.0 * math.sin(math.radians(h)))
            for s in seeds:
                jobs[("goal", h, s)] = pool.submit(drive, binary, [goal], s, 90, args.gaits)
        if not args.no_square:
            square = [(10, 0), (10, 10), (0, 10), (0, 0)]
            for s in seeds:
                jobs[("square", 0, s)] = pool.submit(drive, binary, square, s, 240, args.gaits)
        results = {k: f.result() for k, f in jobs.items()}
    report(results, headings, seeds, args.no_square)


def report(results, headings, seeds, no_square):
    print("| goal heading | seed | reached | time s | miss m | made good m/min | switches | cut-off steps (after a switch) |")
    print("|---|---|---|---|---|---|---|---|")
    reached = speeds = 0
    speed_list = []
    faults = hard = 0
    for h in headings:
        for s in seeds:
            r = results[("goal", h, s)]
            w = r["waypoints"][0]
            made_good = 20.0 / (w["time_s"] / 60.0) if w["reached"] and w["time_s"] > 0 else 0.0
            reached += w["reached"] and w["time_s"] <= 90.0
            speed_list.append(made_good)
            speeds += made_good >= 25.0
            faults += r["faults"]
            hard += r["hard_limit_steps"]
            print(f"| {h:+.0f}° | {s} | {'yes' if w['reached'] else 'no'} | {w['time_s']:.1f} | {w['miss_m']:.2f} | "
                  f"{made_good:.1f} | {r['switches']} | {r['cutoff_steps']} ({r['cutoff_steps_after_switch']}) |")
    n = len(headings) * len(seeds)
    print(f"\ngoals reached within 1.5 m in 90 s: {reached}/{n}; speed made good >= 25 m/min: {speeds}/{n}; "
          f"median {sorted(speed_list)[n // 2]:.1f} m/min, least {min(speed_list):.1f}")
    if not no_square:
        print("\n| square seed | waypoints reached | time s | worst miss m | switches | cut-off steps (after a switch) |")
        print("|---|---|---|---|---|---|")
        for s in seeds:
            r = results[("square", 0, s)]
            misses = [w["miss_m"] for w in r["waypoints"]]
            worst = "never steered to the last" if None in misses else f"{max(misses):.2f}"
            faults += r["faults"]
            hard += r["hard_limit_steps"]
            print(f"| {s} | {r['reached']}/{len(r['waypoints'])} | {r['time_s']:.1f} | {worst} | {r['switches']} | "
                  f"{r['cutoff_steps']} ({r['cutoff_steps_after_switch']}) |")
    print(f"\nend caps faulted: {faults}; steps with a cable above the hard limit: {hard}")


if __name__ == "__main__":
    sys.exit(main())
