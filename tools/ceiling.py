#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""How far can the model roll at the paper's limits, whatever finds the table?

A probe, not a learner the robot uses: CMA-ES (Hansen's (mu/mu_w, lambda) with
rank-one and rank-mu updates) over the whole table of a policy (24 cables x n
values), each candidate played by `tensegrity sim --policy` (the same firmware
core and model the coevolution scores with). It answers one question
(data: docs/results/ceiling/): is 32 m in 60 s reachable on this model at all, or does the
coevolution stop below a ceiling of the model's?

Written here with numpy because Debian 12 packages no CMA-ES (no python3-cma);
it is the textbook algorithm (Hansen, "The CMA Evolution Strategy: A Tutorial",
2016) with the defaults it recommends, and it never ships in a policy by itself:
its best table is re-played and reported like any other policy.
"""

import argparse
import concurrent.futures
import copy
import csv
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np


def play(binary, policy, values, lo, hi, tmpdir, tag):
    """Distance (m) of one candidate; 0 when infeasible, as in the coevolution."""
    p = copy.deepcopy(policy)
    n = p["complexity"]
    clipped = np.clip(values, lo, hi)
    for i, cable in enumerate(p["cables"]):
        cable["rest_lengths_m"] = [float(v) for v in clipped[i * n:(i + 1) * n]]
    path = os.path.join(tmpdir, f"c{tag}.json")
    with open(path, "w") as f:
        json.dump(p, f)
    out = subprocess.run([binary, "sim", "--policy", path, "--json"],
                         check=True, capture_output=True, text=True).stdout
    r = json.loads(out)
    return (r["distance_m"] if r["feasible"] else 0.0), r


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--binary", default="build/release/cli/tensegrity")
    ap.add_argument("--start", required=True,
                    help="policy JSON: its table is the initial mean, its robot and period are kept")
    ap.add_argument("--random-start", action="store_true",
                    help="start from a uniform random table instead of the start policy's values")
    ap.add_argument("--sigma", type=float, default=0.05, help="initial step size, m")
    ap.add_argument("--evaluations", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--out", required=True, help="directory: curve.csv, best.json")
    a = ap.parse_args()

    with open(a.start) as f:
        policy = json.load(f)
    with open(policy_robot_path(a.start, policy)) as f:
        robot = json.load(f)
    lo, hi = rest_length_limits(robot)
    n = policy["complexity"]
    x0 = np.array([v for c in policy["cables"] for v in c["rest_lengths_m"]], dtype=float)
    dim = x0.size
    rng = np.random.default_rng(a.seed)
    if a.random_start:
        x0 = rng.uniform(lo, hi, dim)
    os.makedirs(a.out, exist_ok=True)

    # Hansen's default strategy parameters.
    lam = 4 + int(3 * math.log(dim))
    mu = lam // 2
    w = np.log(mu + 0.5) - np.log(np.arange(1, mu + 1))
    w /= w.sum()
    mueff = 1.0 / np.sum(w ** 2)
    cc = (4 + mueff / dim) / (dim + 4 + 2 * mueff / dim)
    cs = (mueff + 2) / (dim + mueff + 5)
    c1 = 2 / ((dim + 1.3) ** 2 + mueff)
    cmu = min(1 - c1, 2 * (mueff - 2 + 1 / mueff) / ((dim + 2) ** 2 + mueff))
    damps = 1 + 2 * max(0, math.sqrt((mueff - 1) / (dim + 1)) - 1) + cs
    chin = math.sqrt(dim) * (1 - 1 / (4 * dim) + 1 / (21 * dim * dim))

    mean, sigma = x0.copy(), a.sigma
    C = np.eye(dim)
    pc, ps = np.zeros(dim), np.zeros(dim)
    B, D = np.eye(dim), np.ones(dim)
    best, best_x, evals, gen = -1.0, x0.copy(), 0, 0
    t0 = time.time()
    curve = open(os.path.join(a.out, "curve.csv"), "w", newline="")
    log = csv.writer(curve)
    log.writerow(["generation", "evaluations", "best_m", "generation_best_m", "generation_mean_m", "sigma_m"])
    with tempfile.TemporaryDirectory() as tmp, \
            concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        while evals < a.evaluations:
            z = rng.standard_normal((lam, dim))
            y = z @ (B * D).T
            xs = mean + sigma * y
            scores = list(pool.map(lambda i: play(a.binary, policy, xs[i], lo, hi, tmp, i)[0], range(lam)))
            evals += lam
            gen += 1
            order = np.argsort(scores)[::-1]
            if scores[order[0]] > best:
                best, best_x = scores[order[0]], np.clip(xs[order[0]], lo, hi)
            ysel = y[order[:mu]]
            old = mean
            mean = np.clip(mean + sigma * (w @ ysel), lo, hi)
            yw = (mean - old) / sigma
            invsqrt = B @ np.diag(1 / D) @ B.T
            ps = (1 - cs) * ps + math.sqrt(cs * (2 - cs) * mueff) * (invsqrt @ yw)
            hsig = np.linalg.norm(ps) / math.sqrt(1 - (1 - cs) ** (2 * gen)) / chin < 1.4 + 2 / (dim + 1)
            pc = (1 - cc) * pc + hsig * math.sqrt(cc * (2 - cc) * mueff) * yw
            C = ((1 - c1 - cmu) * C + c1 * (np.outer(pc, pc) + (not hsig) * cc * (2 - cc) * C)
                 + cmu * (ysel.T * w) @ ysel)
            sigma *= math.exp((cs / damps) * (np.linalg.norm(ps) / chin - 1))
            C = np.triu(C) + np.triu(C, 1).T
            D2, B = np.linalg.eigh(C)
            D = np.sqrt(np.maximum(D2, 1e-20))
            log.writerow([gen, evals, f"{best:.4f}", f"{scores[order[0]]:.4f}",
                          f"{np.mean(scores):.4f}", f"{sigma:.5f}"])
            curve.flush()
            rate = evals / (time.time() - t0)
            print(f"\rgen {gen} evals {evals} best {best:.2f} m gen mean {np.mean(scores):.2f} m "
                  f"sigma {sigma:.4f} {rate:.1f} ev/s", end="", file=sys.stderr, flush=True)
        _, report = play(a.binary, policy, best_x, lo, hi, tmp, "best")
    print(file=sys.stderr)
    out = copy.deepcopy(policy)
    for i, cable in enumerate(out["cables"]):
        cable["rest_lengths_m"] = [float(v) for v in best_x[i * n:(i + 1) * n]]
    out["provenance"] = dict(policy.get("provenance", {}), method="cma-es probe (tools/ceiling.py)",
                             seed=a.seed, episodes=evals, score_m=best)
    with open(os.path.join(a.out, "best.json"), "w") as f:
        json.dump(out, f, indent=2)
    print(json.dumps({"evaluations": evals, "best_m": best, "replayed_m": report["distance_m"],
                      "mean_tension_n": report["mean_tension_n"], "max_tension_n": report["max_tension_n"],
                      "mean_motor_power_w": report["mean_motor_power_w"]}))


def policy_robot_path(policy_path, policy):
    here = os.path.dirname(os.path.abspath(__file__))
    return os.path.join(here, "..", "robots", policy["robot"] + ".json")


def rest_length_limits(robot):
    def find(o):
        if isinstance(o, dict):
            for k, v in o.items():
                if "rest_length" in k and "min" in k:
                    lo = v
                    hi = next(v2 for k2, v2 in o.items() if "rest_length" in k2 and "max" in k2)
                    return lo, hi
                r = find(v)
                if r:
                    return r
        return None
    r = find(robot)
    if not r:
        sys.exit("robot description: no rest-length limits found")
    return r


if __name__ == "__main__":
    main()
