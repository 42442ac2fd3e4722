#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""tools/plateau.py with the real `tensegrity analyze`: an arm of two seeds, the
shipped rolling gait and a table that holds every cable still, each with a curve.

Usage: plateau_test.py TOOLS_DIR TENSEGRITY SOURCE_DIR
"""
import csv
import json
import pathlib
import shutil
import subprocess
import sys
import tempfile
import unittest

TOOLS, TENSEGRITY, SOURCE = (pathlib.Path(x) for x in sys.argv[1:4])
del sys.argv[1:4]

HEADER = "generation,episodes,best_score_m,mean_score_m,infeasible_rate,best_so_far_m,teams,infeasible\n"


def seed(arm, name, policy, bests_and_means):
    run = arm / "runs" / name
    run.mkdir(parents=True)
    (run / "policy.json").write_text(json.dumps(policy))
    rows = [f"{g + 1},{50 * (g + 1)},{b},{m},0,{b},50,0\n" for g, (b, m) in enumerate(bests_and_means)]
    (run / "curve.csv").write_text(HEADER + "".join(rows))


def make_arm(tmp):
    """An arm directory with the default robot, and the shipped rolling gait."""
    arm = pathlib.Path(tmp) / "arm"
    arm.mkdir()
    shutil.copy(SOURCE / "robots" / "superball-paper.json", arm / "robot.json")
    return arm, json.loads((SOURCE / "policies" / "superball-paper-t4-n5.json").read_text())


class Plateau(unittest.TestCase):
    def test_a_rolling_seed_and_a_still_one(self):
        with tempfile.TemporaryDirectory() as tmp:
            arm, rolling = make_arm(tmp)
            still = json.loads(json.dumps(rolling))
            for cable in still["cables"]:
                cable["rest_lengths_m"] = [0.85] * len(cable["rest_lengths_m"])
            # s1 leaves the plateau at episode 150 (9 -> 24 m) and rolls from 200; s2 never does
            seed(arm, "s1", rolling, [(5, 1), (9, 2), (24, 3.5), (33, 9)])
            seed(arm, "s2", still, [(3, 1), (4, 1.5), (4, 2), (6, 2)])
            out = pathlib.Path(tmp) / "out"
            done = subprocess.run(["/usr/bin/python3", str(TOOLS / "plateau.py"), str(arm), "--out", str(out),
                                   "--tensegrity", str(TENSEGRITY)], capture_output=True, text=True)
            self.assertEqual(done.returncode, 0, done.stderr)
            with open(out / "plateau.csv") as f:
                rows = {r["seed"]: r for r in csv.DictReader(f)}
            s1, s2 = rows["s1"], rows["s2"]
            self.assertEqual((s1["class"], s2["class"]), ("rolls", "plateau"))
            # the shipped gait turns once every two 4 s periods on all 12 end caps
            self.assertAlmostEqual(float(s1["turn_period_s"]), 8.0, delta=0.5)
            self.assertGreater(float(s1["revolutions"]), 6.0)
            self.assertEqual(s1["endcaps_on_ground"], "12")
            self.assertLess(float(s2["distance_m"]), 1.0)
            self.assertLess(float(s2["revolutions"]), 0.5)
            self.assertEqual((s1["takeoff_episode"], s1["first_roll_episode"]), ("150", "200"))
            self.assertEqual((float(s1["best_before_takeoff_m"]), float(s1["best_at_takeoff_m"])), (9.0, 24.0))
            self.assertEqual(float(s1["generation_mean_at_takeoff_m"]), 3.5)
            self.assertEqual(s2["takeoff_episode"], "")
            summary = json.loads((out / "plateau.json").read_text())
            self.assertEqual([summary["classes"][c]["seeds"] for c in ("rolls", "late", "plateau")], [1, 0, 1])
            self.assertEqual(summary["takeoffs"]["seeds"], 1)
            self.assertEqual(summary["takeoffs"]["rolling_in_the_same_generation"], 0)
            self.assertEqual(summary["takeoffs"]["median_episodes_takeoff_to_roll"], 50)
            self.assertTrue((out / "plateau.png").stat().st_size > 0)

    def test_a_damaged_curve_is_named(self):
        with tempfile.TemporaryDirectory() as tmp:
            arm, rolling = make_arm(tmp)
            seed(arm, "s1", rolling, [(5, 1), ("lost", 2)])
            done = subprocess.run(["/usr/bin/python3", str(TOOLS / "plateau.py"), str(arm), "--out", tmp + "/out",
                                   "--tensegrity", str(TENSEGRITY)], capture_output=True, text=True)
            self.assertNotEqual(done.returncode, 0)
            self.assertIn("curve.csv, line 3: best_score_m 'lost' is not a number", done.stderr)

    def test_a_directory_that_is_not_an_arm_is_named(self):
        with tempfile.TemporaryDirectory() as tmp:
            done = subprocess.run(["/usr/bin/python3", str(TOOLS / "plateau.py"), tmp, "--out", tmp + "/out",
                                   "--tensegrity", str(TENSEGRITY)], capture_output=True, text=True)
            self.assertNotEqual(done.returncode, 0)
            self.assertIn("no robot.json", done.stderr)


if __name__ == "__main__":
    unittest.main()
