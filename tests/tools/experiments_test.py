#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""tools/experiments.py's sweeps (Figures 8 and 9), with a stand-in for
`tensegrity evolve` that answers at once: what a point records, and that runs
learned on one robot, or with other evolve settings, are not reused.

Usage: experiments_test.py TOOLS_DIR
"""
import csv
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest

TOOLS = pathlib.Path(sys.argv.pop(1) if len(sys.argv) > 1 else pathlib.Path(__file__).parents[2] / "tools")
sys.path.insert(0, str(TOOLS))
from tensegrity_tools import sweep_figure  # noqa: E402

# Odd seeds roll 35 m, even seeds stay at 8 m plus the period: a bimodal point.
FAKE_EVOLVE = r'''#!/usr/bin/python3
import csv, json, os, sys
args, argv = {}, sys.argv[2:]
for i, token in enumerate(argv):
    if token.startswith("--"):
        args[token] = argv[i + 1] if i + 1 < len(argv) and not argv[i + 1].startswith("--") else ""
seed, period = int(args.get("--seed", 1)), float(args["--period"])
best = 35.0 if seed % 2 else 8.0 + period
with open(args["--log"], "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(["generation", "episodes", "best_score_m", "mean_score_m", "infeasible_rate", "best_so_far_m"])
    w.writerow([1, int(args["--episodes"]), best, best / 2, 0, best])
open(args["--out"], "w").write("{}")
# FAKE_POPULATION stands for another version of the program with other defaults.
config = {"population": int(os.environ.get("FAKE_POPULATION", 40)), "replace": 20, "teams": 50,
          "mutation": "gaussian", "sigma_m": float(args.get("--sigma", 0.05)), "sigma_final_m": 0.02,
          "anneal_start_episodes": 2000, "anneal_episodes": 3000}
print(json.dumps({"final_score_m": best, "episodes": int(args["--episodes"]), "config": config}))
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
    def run_sweep(self, root, robot, check=True, env=None, more=()):
        cmd = [sys.executable, str(TOOLS / "experiments.py"), "--out", str(root / "out"), "--tensegrity",
               str(root / "fake"), "--robot", str(robot), "--figures", "8", "--periods", "4,6",
               "--sweep-seeds", "3", "--sweep-episodes", "100", "--jobs", "2", *more]
        return subprocess.run(cmd, capture_output=True, text=True, check=check,
                              env=None if env is None else dict(os.environ, **env))

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
            settings = json.loads((root / "out" / "evolve-settings.json").read_text())["default"]
            self.assertEqual((settings["population"], settings["sigma_final_m"]), (40, 0.02))
            # a program whose defaults changed is refused before it runs, naming the field
            other_version = self.run_sweep(root, robot, check=False, env={"FAKE_POPULATION": "10"})
            self.assertNotEqual(other_version.returncode, 0)
            self.assertIn("population: 40 -> 10", other_version.stderr)
            # runs with a step of their own get their own ids and settings beside them
            own_step = self.run_sweep(root, robot, more=("--sigma", "0.03"))
            self.assertEqual(own_step.stdout.count("done already"), 0)
            table = json.loads((root / "out" / "evolve-settings.json").read_text())
            self.assertEqual((table["-m0.03"]["sigma_m"], table["default"]["sigma_m"]), (0.03, 0.05))
            # a damaged settings file is named, not a traceback
            (root / "out" / "evolve-settings.json").write_text("{bad")
            damaged = self.run_sweep(root, robot, check=False)
            self.assertIn("evolve-settings.json is not JSON", damaged.stderr)

    def test_a_sweep_run_in_parts_draws_every_finished_run(self):
        with tempfile.TemporaryDirectory() as tmp:
            root = pathlib.Path(tmp)
            (root / "fake").write_text(FAKE_EVOLVE)
            (root / "fake").chmod(0o755)
            robot = root / "robot.json"
            robot.write_text('{"name": "a"}\n')
            self.run_sweep(root, robot)  # t = 4 and 6 s, 3 seeds
            self.run_sweep(root, robot, more=("--periods", "5", "--sweep-seeds", "1"))
            with open(root / "out" / "fig8_period.csv") as f:
                rows = {r["period_s"]: r for r in csv.DictReader(f)}
            self.assertEqual(sorted(rows), ["4", "5", "6"])
            self.assertEqual((rows["4"]["seeds"], rows["5"]["seeds"], rows["6"]["seeds"]), ("3", "1", "3"))
            # its summary counts the runs it draws, not only the last part's
            summary = json.loads((root / "out" / "summary.json").read_text())
            self.assertEqual((summary["runs_done"], summary["runs_planned"]), (7, 7))
            # runs with another step are another experiment: not drawn with these
            self.run_sweep(root, robot, more=("--periods", "7", "--sweep-seeds", "1", "--sigma", "0.03"))
            self.run_sweep(root, robot, more=("--plot-only",))
            with open(root / "out" / "fig8_period.csv") as f:
                self.assertEqual(sorted(r["period_s"] for r in csv.DictReader(f)), ["4", "5", "6"])


if __name__ == "__main__":
    unittest.main()
