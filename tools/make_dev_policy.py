#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""A hand-made development policy (tensegrity-policy/1) for the HIL until the
evolution engineer ships a learned one: period 4 s, complexity 5, cable m's
value j is 0.85 + 0.15 sin(2 pi j / 5 + 2 pi m / 24) m, the benchmark workload's
travelling wave sampled at the table's five subintervals.

usage: tools/make_dev_policy.py OUT.json [robots/superball.json]
"""
import argparse
import json
import math


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="the policy file to write")
    ap.add_argument("robot", nargs="?", default="robots/superball.json", help="robot file (default: %(default)s)")
    args = ap.parse_args()
    out = args.out
    with open(args.robot) as f:
        robot = json.load(f)
    cables = []
    for m, c in enumerate(robot["cables"]):
        values = [round(0.85 + 0.15 * math.sin(2 * math.pi * j / 5 + 2 * math.pi * m / 24), 6) for j in range(5)]
        cables.append({"cable": m, "owner": c["owner"], "rest_lengths_m": values})
    policy = {
        "format": "tensegrity-policy/1",
        "robot": robot["name"],
        "period_s": 4.0,
        "complexity": 5,
        "cables": cables,
        "provenance": {"method": "hand", "created_by": "tools/make_dev_policy.py"},
    }
    with open(out, "w") as f:
        json.dump(policy, f, indent=2)
        f.write("\n")


if __name__ == "__main__":
    main()
