#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""A ground tool never speaks unsecured unless asked: with no keystore named and none
at the default place, every tool that joins the DDS domain stops at once (exit 2)
saying how to get one or to pass --insecure, instead of waiting its whole timeout
for end caps that refuse unsecured participants. --insecure still runs.

Usage: ground_security_test.py TENSEGRITY SOURCE_DIR
"""
import os
import pathlib
import subprocess
import sys
import tempfile
import time
import unittest

TENSEGRITY, SOURCE = sys.argv.pop(1), pathlib.Path(sys.argv.pop(1))
DOMAIN = "221"
# Longer than "at once" can take on a loaded machine, far shorter than the tools' waits.
AT_ONCE_S = 10.0


class GroundToolsWithoutAKeystore(unittest.TestCase):
    def setUp(self):
        self.home = tempfile.TemporaryDirectory()
        self.env = {k: v for k, v in os.environ.items() if k not in ("TENSEGRITY_KEYSTORE", "XDG_DATA_HOME")}
        self.env.update(HOME=self.home.name, XDG_DATA_HOME=os.path.join(self.home.name, "data"),
                        XDG_RUNTIME_DIR=self.home.name, TENSEGRITY_DOMAIN=DOMAIN)

    def tearDown(self):
        self.home.cleanup()

    def run_tool(self, *args):
        started = time.monotonic()
        try:
            done = subprocess.run([TENSEGRITY, *args], capture_output=True, text=True, env=self.env,
                                  stdin=subprocess.DEVNULL, timeout=2 * AT_ONCE_S)
        except subprocess.TimeoutExpired:
            self.fail(f"tensegrity {' '.join(args)}: still running after {2 * AT_ONCE_S} s")
        return done, time.monotonic() - started

    def test_every_tool_refuses_at_once_and_says_how_to_fix_it(self):
        policy = str(SOURCE / "policies" / "superball-paper-t4-n5.json")
        out = os.path.join(self.home.name, "rec.csv")
        for args in (["status", "--once"], ["estop", "--no-console"], ["stop", "--no-console"],
                     ["clear-fault", "--no-console"], ["start"], ["upload", policy], ["record", out],
                     ["console", "--socket", os.path.join(self.home.name, "c.sock")],
                     ["view", "--live", "--port", "0"]):
            if args[0] != "view":
                args = [*args, "--timeout", "30"]
            with self.subTest(tool=args[0]):
                done, took = self.run_tool(*args)
                self.assertEqual(done.returncode, 2, done.stderr)
                self.assertLess(took, AT_ONCE_S, done.stderr)
                for fix in ("tensegrity security init", "--keystore", "TENSEGRITY_KEYSTORE", "--insecure"):
                    self.assertIn(fix, done.stderr)

    def test_a_named_keystore_that_is_not_there_is_refused_too(self):
        self.env["TENSEGRITY_KEYSTORE"] = os.path.join(self.home.name, "nowhere")
        done, _ = self.run_tool("status", "--once", "--timeout", "30")
        self.assertEqual(done.returncode, 2, done.stderr)
        self.assertIn("nowhere", done.stderr)

    def test_insecure_is_the_explicit_way_to_run_unsecured(self):
        done, _ = self.run_tool("status", "--once", "--insecure", "--timeout", "1")
        self.assertEqual(done.returncode, 1, done.stderr)  # no end cap answered: the tool did run
        self.assertNotIn("tensegrity security init", done.stderr)


if __name__ == "__main__":
    unittest.main()
