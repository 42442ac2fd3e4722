#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""How wide is a learned gait's mode? Play tables around it on one or more robots.

Two probes per gait, every table played by `tensegrity sim --policy ... --json` on
every --robot (for instance the same robot on two engines):

- line: K uniform random tables (within the robot's rest-length limits), and the
  straight line from each to the gait at t = 0, 0.1, ..., 1;
- noise: N copies of the gait with every value moved by N(0, sigma), clamped, for
  each --sigma.

Tables come from one random stream (--seed), drawn gait by gait in the order given,
so the same command gives the same tables. Output: OUT/probe.csv (gait, probe, k,
t_or_sigma, robot, distance_m) and a median table on stdout.

  tools/needle_probe.py --out out/needles --gait bullet-s4=ARM/runs/s4/policy.json \\
      --robot bullet=ARM/robot.json --robot ode=ODE_ARM/robot.json
"""
import argparse
import concurrent.futures
import copy
import csv
import json
import pathlib
import random
import statistics
import sys

from tensegrity_tools import program


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True, help="output directory")
    program.add_option(p)
    p.add_argument("--gait", action="append", required=True, metavar="NAME=POLICY", help="a gait (repeatable)")
    p.add_argument("--robot", action="append", required=True, metavar="NAME=ROBOT", help="a robot (repeatable)")
    p.add_argument("--random", type=int, default=5, help="random tables per gait for the line probe")
    p.add_argument("--steps", type=int, default=10, help="segments of each line (default: %(default)s)")
    p.add_argument("--sigma", type=float, action="append", default=None,
                   help="noise probe step, m (repeatable; default 0.01, 0.02, 0.05)")
    p.add_argument("--copies", type=int, default=10, help="noisy copies per sigma (default: %(default)s)")
    p.add_argument("--seed", type=int, default=18)
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--nice", type=int, default=19)
    return p.parse_args()


def named(items, what):
    out = {}
    for item in items:
        if "=" not in item:
            sys.exit(f"--{what} {item}: expected NAME=PATH")
        name, path = item.split("=", 1)
        out[name] = pathlib.Path(path)
    return out


def read_json(path, what):
    try:
        return json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as e:
        sys.exit(f"--{what} {path}: {e}")


def limits(robot_path):
    try:
        cable = read_json(robot_path, "robot")["cable"]
        return float(cable["min_rest_length_m"]), float(cable["max_rest_length_m"])
    except (KeyError, TypeError, ValueError) as e:
        sys.exit(f"--robot {robot_path}: cable.min_rest_length_m / cable.max_rest_length_m: {e}")


def tables_for(gait_doc, rng, args, lo, hi):
    """(probe, k, t_or_sigma, values) in the random stream's order."""
    g = [c["rest_lengths_m"] for c in gait_doc["cables"]]
    for k in range(args.random):
        r = [[rng.uniform(lo, hi) for _ in row] for row in g]
        for i in range(args.steps + 1):
            t = i / args.steps
            yield "line", k, t, [[a + t * (b - a) for a, b in zip(ra, rb)] for ra, rb in zip(r, g)]
    for sigma in args.sigma:
        for k in range(args.copies):
            yield f"noise{sigma}", k, sigma, [[x + rng.gauss(0, sigma) for x in row] for row in g]


def play(args, doc, robot, path):
    path.write_text(json.dumps(doc))
    return program.sim(args.tensegrity, path, robot, nice=args.nice)["distance_m"]


def main():
    args = parse_args()
    args.sigma = args.sigma or [0.01, 0.02, 0.05]
    for name, value in (("--random", args.random), ("--copies", args.copies), ("--jobs", args.jobs)):
        if value < 0 or (name == "--jobs" and value < 1):
            sys.exit(f"{name} {value}: must be {'at least 1' if name == '--jobs' else 'zero or more'}")
    if args.steps < 1:
        sys.exit(f"--steps {args.steps}: must be at least 1")
    if any(not 0 <= sigma <= 1 for sigma in args.sigma):
        sys.exit(f"--sigma {args.sigma}: each must lie in [0, 1] m")
    args.tensegrity = program.find(args.tensegrity)
    gaits, robots = named(args.gait, "gait"), named(args.robot, "robot")
    lo, hi = limits(next(iter(robots.values())))
    out = pathlib.Path(args.out)
    (out / "tables").mkdir(parents=True, exist_ok=True)
    rng = random.Random(args.seed)
    jobs = []
    for gname, gpath in gaits.items():
        gait = read_json(gpath, "gait")
        cables = gait.get("cables") if isinstance(gait, dict) else None
        if not isinstance(cables, list) or not all(isinstance(c, dict) and isinstance(c.get("rest_lengths_m"), list)
                                                   for c in cables):
            sys.exit(f"--gait {gpath}: not a policy file (cables[].rest_lengths_m missing)")
        for probe, k, x, values in tables_for(gait, rng, args, lo, hi):
            doc = copy.deepcopy(gait)
            doc["provenance"] = {"created_by": f"tools/needle_probe.py: {probe} {k} at {x} around {gpath}"}
            for cable, row in zip(doc["cables"], values):
                cable["rest_lengths_m"] = [min(hi, max(lo, v)) for v in row]
            for rname, rpath in robots.items():
                jobs.append(((gname, probe, k, x, rname), doc, rpath))
    print(f"needle_probe: {len(jobs)} episodes", file=sys.stderr)
    with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
        distances = list(pool.map(lambda j: play(args, j[1], j[2], out / "tables" / ("_".join(map(str, j[0])) + ".json")),
                                  jobs))
    with open(out / "probe.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["gait", "probe", "k", "t_or_sigma", "robot", "distance_m"])
        for (key, _, _), d in zip(jobs, distances):
            w.writerow(list(key) + [f"{d:.3f}"])
    cells = {}
    for (key, _, _), d in zip(jobs, distances):
        cells.setdefault((key[0], key[4], key[1], key[3]), []).append(d)
    for (gname, rname, probe, x), values in cells.items():
        print(f"{gname} on {rname}: {probe} at {x}: median {statistics.median(values):.2f} m, best {max(values):.2f} m")


if __name__ == "__main__":
    main()
