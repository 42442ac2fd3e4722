#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""`tensegrity drive --sim` as a user runs it, on a short course the shipped policy's
first gait rolls along (13 s and 23 s of physics): each waypoint reached by the model's
true centre, the JSON fields, the same seed driving the same course, the path record,
and bad input named.

  drive_sim_test.py TENSEGRITY SOURCE_DIR
"""
import csv
import json
import os
import subprocess
import sys
import tempfile

COURSE = ["--to", "7,-2.2", "--to", "11.5,-5.5"]


def run(binary, args, cwd):
    return subprocess.run([binary, "drive", *args], capture_output=True, text=True, cwd=cwd, timeout=120, check=False)


def check_course(binary, cwd, record):
    out = run(binary, ["--sim", "--json", "--seed", "2", "--record", record, *COURSE], cwd)
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert doc["completed"] is True and doc["reached"] == 2, doc
    for w in doc["waypoints"]:
        assert w["reached"] is True and 0.0 <= w["miss_m"] <= doc["within_m"], w
        assert 0.0 < w["time_s"] <= 45.0, w
    assert doc["waypoints"][0]["time_s"] < doc["waypoints"][1]["time_s"], doc
    assert doc["faults"] == 0 and doc["hard_limit_steps"] == 0, doc
    for key in ("time_s", "periods", "switches", "cutoff_steps", "cutoff_steps_after_switch", "face_changes"):
        assert key in doc, key
    again = run(binary, ["--sim", "--json", "--seed", "2", *COURSE], cwd)
    assert json.loads(again.stdout) == doc, "the same seed must drive the same course"
    with open(record, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) > 100 and {"x_m", "estimate_x_m", "face", "estimate_face", "gait"} <= rows[0].keys(), rows[:1]
    # The estimate follows the fixes: within a metre of the truth once the robot rolls.
    worst = max(abs(float(r["x_m"]) - float(r["estimate_x_m"])) for r in rows[20:])
    assert worst < 1.0, worst


def check_errors(binary, cwd):
    bad = run(binary, ["--sim", "--to", "7"], cwd)
    assert bad.returncode == 2 and "--to #1" in bad.stderr, bad.stderr
    bad = run(binary, ["--sim", "--to", "1,1", "--to", "2,y"], cwd)
    assert bad.returncode == 2 and "--to #2" in bad.stderr and "Y" in bad.stderr, bad.stderr
    no_sim = run(binary, ["--to", "1,1"], cwd)
    assert no_sim.returncode == 2 and "--sim" in no_sim.stderr, no_sim.stderr
    missed = run(binary, ["--sim", "--json", "--time-limit", "2", "--to", "20,0"], cwd)
    doc = json.loads(missed.stdout)
    assert missed.returncode == 1 and doc["completed"] is False and doc["waypoints"][0]["reached"] is False, doc


def main():
    binary, source = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as tmp:
        check_course(binary, source, os.path.join(tmp, "path.csv"))
    check_errors(binary, source)
    print("drive --sim: ok")


if __name__ == "__main__":
    main()
