#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""`tensegrity bench sim|evolve --json` report the ratios the speed targets name: the
benchmark episode at the step asked for against 1000x real time, the same episode at
1 ms against the Bullet engine's model of the same robot, and for evolution the wall
time 5000 episodes would take and the resident memory.

Usage: bench_test.py TENSEGRITY SOURCE_DIR
"""
import json
import pathlib
import subprocess
import sys
import tempfile
import unittest

TENSEGRITY, SOURCE = sys.argv.pop(1), pathlib.Path(sys.argv.pop(1))
ROBOT = SOURCE / "robots" / "superball.json"


def run_json(*args):
    done = subprocess.run([TENSEGRITY, *args, "--json"], capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def benchmark_distance(robot, dt_s):
    return run_json("sim", "--benchmark-policy", "--robot", str(robot), "--start", "drop", "--duration", "1",
                    "--dt", str(dt_s))["distance_m"]


class BenchSim(unittest.TestCase):
    def test_the_episode_runs_at_the_step_asked_for_and_bullet_plays_it_at_1ms(self):
        out = run_json("bench", "sim", "--robot", str(ROBOT), "--episodes", "1", "--duration", "1", "--dt", "0.004")
        self.assertEqual(out["dt_s"], 0.004)
        self.assertEqual(out["distance_m"], benchmark_distance(ROBOT, 0.004))
        self.assertAlmostEqual(out["ratio_to_target"], out["real_time_factor"] / 1000.0)
        peers = out["at_1ms"]
        self.assertEqual(peers["ode"]["distance_m"], benchmark_distance(ROBOT, 0.001))
        with tempfile.TemporaryDirectory() as tmp:
            bullet = json.loads(ROBOT.read_text())
            bullet["engine"] = "bullet"
            path = pathlib.Path(tmp) / "superball-bullet.json"
            path.write_text(json.dumps(bullet))
            self.assertEqual(peers["bullet"]["distance_m"], benchmark_distance(path, 0.001))
        self.assertNotEqual(peers["bullet"]["distance_m"], peers["ode"]["distance_m"])
        speedup = peers["bullet"]["median_wall_s"] / peers["ode"]["median_wall_s"]
        self.assertAlmostEqual(peers["speedup_over_bullet"], speedup)
        self.assertAlmostEqual(peers["ratio_to_target"], speedup / 3.5)

    def test_no_bullet_skips_the_comparison(self):
        out = run_json("bench", "sim", "--robot", str(ROBOT), "--episodes", "1", "--duration", "0.5", "--no-bullet")
        self.assertNotIn("at_1ms", out)


class BenchEvolve(unittest.TestCase):
    def test_it_projects_5000_episodes_and_prints_resident_memory(self):
        out = run_json("bench", "evolve", "--episodes", "4", "--duration", "0.5", "--threads", "1")
        self.assertAlmostEqual(out["projected_5000_episodes_wall_s"], 5000 / out["episodes_per_s"])
        self.assertAlmostEqual(out["ratio_to_target"], 180.0 / out["projected_5000_episodes_wall_s"])
        self.assertGreater(out["rss_kb"], 1000)
        self.assertGreater(out["max_rss_kb"], 1000)


if __name__ == "__main__":
    unittest.main()
