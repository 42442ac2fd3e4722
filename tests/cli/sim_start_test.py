#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""`tensegrity sim` names the start it played from, in its JSON (`start`: the robot
file's `start.pose` and `start.settle_s`) and in its readable first line: two robot
files settle from different poses, and a reader of either output must see which.

Usage: sim_start_test.py TENSEGRITY SOURCE_DIR
"""
import json
import pathlib
import subprocess
import sys
import unittest

TENSEGRITY, SOURCE = sys.argv.pop(1), pathlib.Path(sys.argv.pop(1))


def sim(*args):
    done = subprocess.run([TENSEGRITY, "sim", "--duration", "0.05", *args], capture_output=True, text=True,
                          check=True)
    return done.stdout


class SimStart(unittest.TestCase):
    def test_the_settled_start_names_the_robot_files_pose(self):
        for robot, pose, settle_s in [("superball-spin-held.json", "description", 2.0),
                                      ("superball.json", "face_down", 8.0)]:
            with self.subTest(robot=robot):
                out = json.loads(sim("--robot", str(SOURCE / "robots" / robot), "--start", "settled", "--json"))
                self.assertEqual(out["start"], {"kind": "settled", "pose": pose, "settle_s": settle_s})

    def test_the_drop_start_is_the_descriptions_pose(self):
        out = json.loads(sim("--robot", str(SOURCE / "robots/superball.json"), "--start", "drop", "--json"))
        self.assertEqual(out["start"], {"kind": "drop", "pose": "description"})

    def test_the_readable_line_says_the_same(self):
        first = sim("--robot", str(SOURCE / "robots/superball-spin-held.json"), "--start", "settled").splitlines()[0]
        self.assertIn("settled start (the description's pose, 2 s)", first)
        first = sim("--robot", str(SOURCE / "robots/superball.json"), "--start", "settled").splitlines()[0]
        self.assertIn("settled start (a cable triangle face down, 8 s)", first)


if __name__ == "__main__":
    unittest.main()
