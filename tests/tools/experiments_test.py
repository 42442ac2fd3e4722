#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""tools/experiments.py's sweeps (Figures 8 and 9), with a stand-in for
`tensegrity evolve` that answers at once: what a point records, and that runs
learned on one robot are not reused for another.

Usage: experiments_test.py TOOLS_DIR
"""
import csv
import json
import pathlib
import subprocess
import sys
import tempfile
import unittest

TOOLS = pathlib.Path(sys.argv.pop(1) if len(sys.argv) > 1 else pathlib.Path(__file__).parents[2] / "tools")
sys.path.insert(0, str(TOOLS))
import sweep_figure  # noqa: E402

# Odd seeds roll 35 m, even seeds stay at 8 m plus the period: a bimodal point.
FAKE_EVOLVE = r'''#!/usr/bin/python3
import csv, json, sys
args = dict(zip(sys.argv[2::2], sys.argv[3::2]))
seed, period = int(args["--seed"]), float(args["--period"])
best = 35.0 if seed % 2 else 8.0 + period
with open(args["--log"], "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["generation", "episodes", "best_score_m", "mean_score_m", "infeasible_rate", "best_so_far_m"])
    w.writerow([1, int(args["--episodes"]), best, best / 2, 0, best])
open(args["--out"], "w").write("{}")
print(json.dumps({"final_score_m": best, "episodes": int(args["--episodes"])}))
'''


class Point(unittest.TestCase):
    def test_a_bimodal_point_keeps_its_seeds(self):
        p = sweep_figure.point({1: 35.0, 2: 8.0, 3: 36.0, 4: 7.0, 5: 9.0})
        self.assertEqual(p["seeds"], 5)
        self.assertEqual(p["median_m"], 9.0)
        self.assertEqual((p["q1_m"], p["q3_m"]), (8.0, 35.0))
        self.assertEqual(p["seeds_ge_32"], 2)
        self.assertAlmostEqual(p["mean_m"], 19.0)
        self.assertEqual(list(p["per_seed"]), [1, 2, 3, 4, 5])

    def test_an_empty_point(self):
        self.assertEqual(sweep_figure.point({}), {"seeds": 0})


class Sweep(unittest.TestCase):
    def run_sweep(self, root, robot, check=True):
        cmd = [sys.executable, str(TOOLS / "experiments.py"), "--out", str(root / "out"), "--tensegrity",
               str(root / "fake"), "--robot", str(robot), "--figures", "8", "--periods", "4,6",
               "--sweep-seeds", "3", "--sweep-episodes", "100", "--jobs", "2"]
        return subprocess.run(cmd, capture_output=True, text=True, check=check)

    def test_each_point_records_every_seed_and_another_robot_is_refused(self):
        with tempfile.TemporaryDirectory() as tmp:
            root = pathlib.Path(tmp)
            (root / "fake").write_text(FAKE_EVOLVE)
            (root / "fake").chmod(0o755)
            robot, other = root / "robot.json", root / "other.json"
            robot.write_text('{"name": "a"}\n')
            other.write_text('{"name": "b"}\n')
            self.run_sweep(root, robot)
            with open(root / "out" / "fig8_period.csv") as f:
                rows = {r["period_s"]: r for r in csv.DictReader(f)}
            self.assertEqual(rows["4"]["per_seed_m"], "s1:35.00 s2:12.00 s3:35.00")
            self.assertEqual((rows["4"]["seeds"], rows["4"]["seeds_ge_32m"]), ("3", "2"))
            self.assertAlmostEqual(float(rows["6"]["median_m"]), 35.0)
            self.assertAlmostEqual(float(rows["6"]["best_m"]), (35 + 14 + 35) / 3, places=3)
            self.assertEqual(rows["4"]["paper_m"], "33.0")
            summary = json.loads((root / "out" / "summary.json").read_text())
            self.assertEqual(summary["period"]["6"]["seeds_ge_32"], 2)
            self.assertEqual(json.loads((root / "out" / "robot.json").read_text()), {"name": "a"})
            refused = self.run_sweep(root, other, check=False)
            self.assertNotEqual(refused.returncode, 0)
            self.assertIn("robot.json", refused.stderr)
            missing = self.run_sweep(root, root / "nowhere.json", check=False)
            self.assertNotEqual(missing.returncode, 0)
            self.assertIn("nowhere.json: no such file", missing.stderr)
            # the same robot again reuses every finished run
            again = self.run_sweep(root, robot)
            self.assertEqual(again.stdout.count("done already"), 6)


if __name__ == "__main__":
    unittest.main()
