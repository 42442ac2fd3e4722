#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""`tensegrity evolve --dt`: teams are scored at the step asked for, the step is in
the config a checkpoint keeps, and the policy file holds the distance the best team
rolls at the robot's own step, which is what `tensegrity sim` replays.

Usage: evolve_dt_test.py TENSEGRITY SOURCE_DIR
"""
import json
import pathlib
import subprocess
import sys
import tempfile
import unittest

TENSEGRITY, SOURCE = sys.argv.pop(1), pathlib.Path(sys.argv.pop(1))
SMALL = ["--period", "1", "--complexity", "2", "--population", "4", "--replace", "2", "--teams", "4", "--seed", "3",
         "--threads", "1", "--duration", "1", "--episodes", "8"]


def run(*args):
    return subprocess.run([TENSEGRITY, *args], capture_output=True, text=True, check=True).stdout


class EvolveDt(unittest.TestCase):
    def evolve(self, tmp, *extra):
        out = json.loads(run("evolve", *SMALL, "--out", f"{tmp}/p.json", "--log", f"{tmp}/c.csv",
                             "--checkpoint", f"{tmp}/ckpt", "--json", *extra))
        return out, json.loads(pathlib.Path(f"{tmp}/p.json").read_text())

    def test_teams_are_scored_at_the_step_and_the_policy_at_the_robots(self):
        with tempfile.TemporaryDirectory() as tmp:
            out, policy = self.evolve(tmp, "--dt", "0.004")
            self.assertEqual(out["config"]["dt_s"], 0.004)
            replay = json.loads(run("sim", "--policy", f"{tmp}/p.json", "--duration", "1", "--json"))
            self.assertEqual(policy["provenance"]["score_m"], replay["distance_m"])
            self.assertEqual(out["robot_step_score_m"], replay["distance_m"])
            self.assertNotEqual(out["final_score_m"], replay["distance_m"])
            at_dt = json.loads(run("sim", "--policy", f"{tmp}/p.json", "--duration", "1", "--dt", "0.004", "--json"))
            self.assertEqual(out["final_score_m"], at_dt["distance_m"])
            # A checkpoint made at one step does not continue at another.
            with self.assertRaises(subprocess.CalledProcessError):
                self.evolve(tmp, "--resume")

    def test_without_dt_the_robots_learning_step(self):
        learning = json.loads((SOURCE / "robots" / "superball-paper.json").read_text())["learning"]
        with tempfile.TemporaryDirectory() as tmp:
            out, policy = self.evolve(tmp)
            self.assertEqual(out["config"]["dt_s"], learning["time_step_s"])
            replay = json.loads(run("sim", "--policy", f"{tmp}/p.json", "--duration", "1", "--json"))
            self.assertEqual(policy["provenance"]["score_m"], replay["distance_m"])

    def test_a_robot_without_a_learning_step_learns_at_its_own_and_no_field(self):
        robot = SOURCE / "robots" / "superball-spin-held.json"
        self.assertNotIn("learning", json.loads(robot.read_text()))
        with tempfile.TemporaryDirectory() as tmp:
            out, policy = self.evolve(tmp, "--robot", str(robot))
            self.assertNotIn("dt_s", out["config"])
            self.assertEqual(policy["provenance"]["score_m"], out["final_score_m"])


if __name__ == "__main__":
    unittest.main()
