#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""tools/tensegrity_tools/arm_stats.py and tools/arm.py --compare on arms made up here.

Usage: arm_test.py TOOLS_DIR
"""
import csv
import math
import pathlib
import subprocess
import sys
import tempfile
import unittest

TOOLS = pathlib.Path(sys.argv.pop(1) if len(sys.argv) > 1 else pathlib.Path(__file__).parents[2] / "tools")
sys.path.insert(0, str(TOOLS))
from tensegrity_tools import arm_keep, arm_stats  # noqa: E402


def write_arm(root, name, seeds):
    """An arm of `seeds` curves: (best at the plateau, episode it jumps to 35 m or None)."""
    for s, (plateau, jump) in enumerate(seeds, start=1):
        run = root / name / "runs" / f"s{s}"
        run.mkdir(parents=True)
        with open(run / "curve.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["generation", "episodes", "best_score_m", "mean_score_m", "infeasible_rate",
                        "best_so_far_m", "teams", "infeasible"])
            for g in range(1, 41):
                episodes = 50 * g
                best = 35.0 if jump is not None and episodes >= jump else plateau
                w.writerow([g, episodes, best, best / 2, 0, best, 50, 0])
    return root / name


class LogRank(unittest.TestCase):
    def test_one_event_against_one_censored_seed(self):
        # At the one event both seeds are at risk: O = 1, E = 1/2, V = 1/4, chi2 = 1.
        observed, expected, chi2, p = arm_stats.logrank([100], [None])
        self.assertEqual((observed, expected), (1, 0.5))
        self.assertAlmostEqual(chi2, 1.0)
        self.assertAlmostEqual(p, 0.3173105078629141)

    def test_tied_events_use_the_hypergeometric_variance(self):
        # Both of a's seeds at episode 100, b's censored: E = 1, V = 2 (1/2)(1/2)(2/3).
        observed, expected, chi2, p = arm_stats.logrank([100, 100], [None, None])
        self.assertEqual((observed, expected), (2, 1.0))
        self.assertAlmostEqual(chi2, 3.0)
        self.assertAlmostEqual(p, math.erfc(math.sqrt(1.5)))

    def test_identical_groups_are_level(self):
        times = [300, 700, None, 1200, None]
        self.assertAlmostEqual(arm_stats.logrank(times, list(times))[3], 1.0)

    def test_no_events_at_all(self):
        self.assertEqual(arm_stats.logrank([None] * 3, [None] * 3)[3], 1.0)

    def test_earlier_events_are_significant_and_the_tail_matches_scipy(self):
        from scipy.stats import chi2 as chi2_dist
        sooner = [100, 150, 200, 250, 300, 350, 400, 450, 500, None]
        later = [900, None, None, None, None, None, None, None, None, None]
        _, _, chi2, p = arm_stats.logrank(sooner, later)
        self.assertLess(p, 0.01)
        self.assertAlmostEqual(p, chi2_dist.sf(chi2, 1), places=12)
        # Symmetric: swapping the groups changes the sign of O - E, not the p.
        self.assertAlmostEqual(arm_stats.logrank(later, sooner)[3], p)


class Compare(unittest.TestCase):
    def test_every_arm_is_tested_against_the_first(self):
        with tempfile.TemporaryDirectory() as tmp:
            root = pathlib.Path(tmp)
            control = write_arm(root, "control", [(5.0 + 0.1 * s, None) for s in range(10)])
            better = write_arm(root, "better", [(6.0, 500 + 50 * s) for s in range(10)])
            same = write_arm(root, "same", [(5.0 + 0.1 * s, None) for s in range(10)])
            out = root / "cmp"
            done = subprocess.run([sys.executable, str(TOOLS / "arm.py"), "--compare", str(control), str(better),
                                   str(same), "--out", str(out), "--at", "2000"],
                                  capture_output=True, text=True, check=True)
            with open(out / "compare.csv") as f:
                rows = {r["arm"]: r for r in csv.DictReader(f)}
            self.assertEqual(rows["control"]["p_mann_whitney"], "")
            self.assertLess(float(rows["better"]["p_mann_whitney"]), 0.001)
            self.assertLess(float(rows["better"]["p_fisher_28"]), 0.001)
            self.assertLess(float(rows["better"]["p_logrank_32"]), 0.001)
            self.assertTrue(math.isclose(float(rows["same"]["p_fisher_28"]), 1.0))
            self.assertTrue(math.isclose(float(rows["same"]["p_logrank_32"]), 1.0))
            self.assertGreater(float(rows["same"]["p_mann_whitney"]), 0.9)
            self.assertIn("vs control", done.stdout)
            # Comparing reads the arms: their own summaries are not rewritten.
            self.assertFalse((control / "arm.json").exists())
            # A control without runs is an error, not a quiet change of control.
            typo = subprocess.run([sys.executable, str(TOOLS / "arm.py"), "--compare", str(root / "contrl"),
                                   str(better), "--out", str(out)], capture_output=True, text=True)
            self.assertNotEqual(typo.returncode, 0)
            self.assertIn("contrl", typo.stderr)

    def test_a_recorded_arm_csv_is_the_same_control_as_its_runs(self):
        with tempfile.TemporaryDirectory() as tmp:
            root = pathlib.Path(tmp)
            control = write_arm(root, "control", [(5.0 + 0.1 * s, 900 if s < 3 else None) for s in range(10)])
            better = write_arm(root, "better", [(6.0, 500 + 50 * s) for s in range(10)])
            arm = [sys.executable, str(TOOLS / "arm.py")]
            subprocess.run(arm + ["--out", str(control), "--summary-only", "--at", "1000", "--at", "2000"],
                           capture_output=True, check=True)
            recorded = root / "control-2000.csv"
            (control / "arm.csv").rename(recorded)

            def p_values(control_arm, out):
                subprocess.run(arm + ["--compare", str(control_arm), str(better), "--out", str(root / out),
                                      "--at", "2000"], capture_output=True, check=True)
                with open(root / out / "compare.csv") as f:
                    rows = list(csv.DictReader(f))
                self.assertEqual([r["budget"] for r in rows], ["2000", "2000"])  # only the budget asked for
                return {k: v for k, v in rows[1].items() if k.startswith("p_")}

            from_runs, from_csv = p_values(control, "cmp-runs"), p_values(recorded, "cmp-csv")
            self.assertEqual(from_runs, from_csv)
            # The recorded first episodes (900 in three seeds, blank in seven) are read back as such.
            expected = arm_stats.logrank([500 + 50 * s for s in range(10)], [900] * 3 + [None] * 7)[3]
            self.assertAlmostEqual(float(from_csv["p_logrank_32"]), expected, places=12)
            # Another CSV, or a damaged row, is refused by name, not with a traceback.
            (root / "other.csv").write_text("budget,seed,best_m\n1000,1,5.0\n")
            (root / "bad.csv").write_text(recorded.read_text().replace("2000,1,", "2000,x,", 1))
            for name, says in (("other.csv", "first_episode_32m"), ("bad.csv", "line")):
                refused = subprocess.run(arm + ["--compare", str(root / name), str(better), "--out", str(root / "c")],
                                         capture_output=True, text=True)
                self.assertNotEqual(refused.returncode, 0)
                self.assertIn(says, refused.stderr)
                self.assertNotIn("Traceback", refused.stderr)


class Keep(unittest.TestCase):
    def test_packed_runs_restore_the_checkpoint_byte_for_byte(self):
        with tempfile.TemporaryDirectory() as tmp:
            root = pathlib.Path(tmp)
            arm = write_arm(root, "arm", [(5.0, None), (6.0, 800)])
            (arm / "robot.json").write_text('{"name": "r"}\n')
            checkpoint = '{"generation": 40, "members": [' + ", ".join(["0.85"] * 5000) + "]}\n"
            for s in (1, 2):
                run = arm / "runs" / f"s{s}"
                (run / "ckpt").mkdir()
                (run / "ckpt" / "checkpoint.json").write_text(checkpoint.replace("40", str(39 + s)))
                (run / "ckpt" / "checkpoint.prev.json").write_text("older")
                (run / "stderr.log").write_text("")
            subprocess.run([sys.executable, str(TOOLS / "arm.py"), "--out", str(arm), "--summary-only",
                            "--at", "1000", "--pack", str(root / "kept")], capture_output=True, check=True)
            kept = root / "kept"
            self.assertEqual((kept / "robot.json").read_text(), '{"name": "r"}\n')
            self.assertTrue((kept / "arm.csv").exists())
            for s in (1, 2):
                run = kept / "runs" / f"s{s}"
                self.assertEqual(sorted(p.name for p in run.iterdir()), ["ckpt", "curve.csv"])
                packed = run / "ckpt" / "checkpoint.json.xz"
                self.assertEqual([p.name for p in (run / "ckpt").iterdir()], [packed.name])
                self.assertLess(packed.stat().st_size, len(checkpoint) // 5)
                self.assertTrue(arm_keep.unpack_checkpoint(run))
                self.assertEqual((run / "ckpt" / "checkpoint.json").read_text(),
                                 checkpoint.replace("40", str(39 + s)))
                self.assertFalse(arm_keep.unpack_checkpoint(run))  # a checkpoint already there is kept
            with self.assertRaises(ValueError):
                arm_keep.pack(arm, arm)
            # A damaged packed checkpoint is named, and left for another try.
            damaged = kept / "runs" / "s1" / "ckpt"
            (damaged / "checkpoint.json").unlink()
            (damaged / "checkpoint.json.xz").write_bytes(b"not xz")
            with self.assertRaisesRegex(ValueError, "s1/ckpt/checkpoint.json.xz: not a readable xz"):
                arm_keep.unpack_checkpoint(kept / "runs" / "s1")
            self.assertEqual((damaged / "checkpoint.json.xz").read_bytes(), b"not xz")
            self.assertFalse((damaged / "checkpoint.json").exists())


if __name__ == "__main__":
    unittest.main()
