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
import sys
import tempfile
import time

import numpy as np

from tensegrity_tools import program


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
    r = program.sim(binary, path)
    return (r["distance_m"] if r["feasible"] else 0.0), r


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    program.add_option(ap)
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
    a.tensegrity = program.find(a.tensegrity)
    return a


class CmaEs:
    """Hansen's (mu/mu_w, lambda)-CMA-ES with his default strategy parameters; the
    mean is kept within [lo, hi]."""

    def __init__(self, x0, sigma, lo, hi):
        dim = x0.size
        self.dim, self.lo, self.hi = dim, lo, hi
        self.lam = 4 + int(3 * math.log(dim))
        self.mu = self.lam // 2
        w = np.log(self.mu + 0.5) - np.log(np.arange(1, self.mu + 1))
        self.w = w / w.sum()
        self.mueff = 1.0 / np.sum(self.w ** 2)
        self.cc = (4 + self.mueff / dim) / (dim + 4 + 2 * self.mueff / dim)
        self.cs = (self.mueff + 2) / (dim + self.mueff + 5)
        self.c1 = 2 / ((dim + 1.3) ** 2 + self.mueff)
        self.cmu = min(1 - self.c1, 2 * (self.mueff - 2 + 1 / self.mueff) / ((dim + 2) ** 2 + self.mueff))
        self.damps = 1 + 2 * max(0, math.sqrt((self.mueff - 1) / (dim + 1)) - 1) + self.cs
        self.chin = math.sqrt(dim) * (1 - 1 / (4 * dim) + 1 / (21 * dim * dim))
        self.mean, self.sigma, self.gen = x0.copy(), sigma, 0
        self.C = np.eye(dim)
        self.pc, self.ps = np.zeros(dim), np.zeros(dim)
        self.B, self.D = np.eye(dim), np.ones(dim)

    def ask(self, rng):
        """lam steps y (in the mean's frame) and the candidates mean + sigma y."""
        y = rng.standard_normal((self.lam, self.dim)) @ (self.B * self.D).T
        return y, self.mean + self.sigma * y

    def tell(self, y, order):
        """Updates mean, paths, covariance and step from the steps ranked best first."""
        self.gen += 1
        ysel = y[order[:self.mu]]
        old = self.mean
        self.mean = np.clip(self.mean + self.sigma * (self.w @ ysel), self.lo, self.hi)
        yw = (self.mean - old) / self.sigma
        invsqrt = self.B @ np.diag(1 / self.D) @ self.B.T
        cs, cc, mueff = self.cs, self.cc, self.mueff
        self.ps = (1 - cs) * self.ps + math.sqrt(cs * (2 - cs) * mueff) * (invsqrt @ yw)
        hsig = (np.linalg.norm(self.ps) / math.sqrt(1 - (1 - cs) ** (2 * self.gen)) / self.chin
                < 1.4 + 2 / (self.dim + 1))
        self.pc = (1 - cc) * self.pc + hsig * math.sqrt(cc * (2 - cc) * mueff) * yw
        self.C = ((1 - self.c1 - self.cmu) * self.C
                  + self.c1 * (np.outer(self.pc, self.pc) + (not hsig) * cc * (2 - cc) * self.C)
                  + self.cmu * (ysel.T * self.w) @ ysel)
        self.sigma *= math.exp((cs / self.damps) * (np.linalg.norm(self.ps) / self.chin - 1))
        self.C = np.triu(self.C) + np.triu(self.C, 1).T
        D2, self.B = np.linalg.eigh(self.C)
        self.D = np.sqrt(np.maximum(D2, 1e-20))


def search(a, policy, x0, lo, hi, rng, tmp):
    """Runs the CMA-ES for --evaluations episodes, a row of OUT/curve.csv per generation;
    returns (best distance, its table, evaluations)."""
    es = CmaEs(x0, a.sigma, lo, hi)
    best, best_x, evals = -1.0, x0.copy(), 0
    t0 = time.time()
    with open(os.path.join(a.out, "curve.csv"), "w", newline="") as curve, \
            concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
        log = csv.writer(curve)
        log.writerow(["generation", "evaluations", "best_m", "generation_best_m", "generation_mean_m", "sigma_m"])
        while evals < a.evaluations:
            y, xs = es.ask(rng)
            scores = list(pool.map(lambda i: play(a.tensegrity, policy, xs[i], lo, hi, tmp, i)[0], range(es.lam)))
            evals += es.lam
            order = np.argsort(scores)[::-1]
            if scores[order[0]] > best:
                best, best_x = scores[order[0]], np.clip(xs[order[0]], lo, hi)
            es.tell(y, order)
            log.writerow([es.gen, evals, f"{best:.4f}", f"{scores[order[0]]:.4f}",
                          f"{np.mean(scores):.4f}", f"{es.sigma:.5f}"])
            curve.flush()
            rate = evals / (time.time() - t0)
            print(f"\rgen {es.gen} evals {evals} best {best:.2f} m gen mean {np.mean(scores):.2f} m "
                  f"sigma {es.sigma:.4f} {rate:.1f} ev/s", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    return best, best_x, evals


def main():
    a = parse_args()
    with open(a.start) as f:
        policy = json.load(f)
    with open(policy_robot_path(a.start, policy)) as f:
        robot = json.load(f)
    lo, hi = rest_length_limits(robot)
    n = policy["complexity"]
    x0 = np.array([v for c in policy["cables"] for v in c["rest_lengths_m"]], dtype=float)
    rng = np.random.default_rng(a.seed)
    if a.random_start:
        x0 = rng.uniform(lo, hi, x0.size)
    os.makedirs(a.out, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        best, best_x, evals = search(a, policy, x0, lo, hi, rng, tmp)
        _, report = play(a.tensegrity, policy, best_x, lo, hi, tmp, "best")
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
    return os.path.join(program.ROOT, "robots", policy["robot"] + ".json")


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
