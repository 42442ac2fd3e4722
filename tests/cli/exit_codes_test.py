#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""`tensegrity` exits with the documented codes (docs/reference/tensegrity.md, "Exit
codes"): 0 for help, 2 for a command line refused by the parser or by the command
itself, 1 for a command that ran and failed.

Usage: exit_codes_test.py TENSEGRITY SOURCE_DIR
"""
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest

TENSEGRITY, SOURCE = sys.argv.pop(1), pathlib.Path(sys.argv.pop(1))


def run(*args):
    return subprocess.run([TENSEGRITY, *args], capture_output=True, text=True, timeout=60)


class ExitCodes(unittest.TestCase):
    def test_help_is_ok(self):
        self.assertEqual(run("--help").returncode, 0)
        self.assertEqual(run("sim", "--help").returncode, 0)

    def test_a_value_the_parser_refuses_is_usage(self):
        # CLI11 alone would exit 105 (a value out of range) and 106 (a missing option).
        done = run("sim", "--duration", "-1")
        self.assertEqual(done.returncode, 2, done.stderr)
        done = run("evolve", "--log", "x.csv")
        self.assertEqual(done.returncode, 2, done.stderr)
        self.assertIn("--out", done.stderr)

    def test_a_value_the_command_refuses_is_usage(self):
        done = run("hil", "--speed", "0.001")
        self.assertEqual(done.returncode, 2, done.stderr)
        self.assertIn("--speed", done.stderr)

    def test_a_command_that_ran_and_failed_is_failure(self):
        with tempfile.TemporaryDirectory() as d:
            out = pathlib.Path(d) / "missing" / "dir" / "run.csv"
            (pathlib.Path(d) / "missing").write_text("a file where a directory should be")
            done = run("sim", "--duration", "0.05", "--telemetry", str(out))
            self.assertEqual(done.returncode, 1, done.stderr)

    def test_the_reference_lists_the_codes_the_header_names(self):
        header = (SOURCE / "core" / "exit_code.hpp").read_text()
        codes = dict((name, int(value)) for name, value in re.findall(r"^\s+(\w+) = (\d+),", header, flags=re.M))
        reference = (SOURCE / "docs" / "reference" / "tensegrity.md").read_text()
        rows = dict((name, int(value)) for value, name in re.findall(r"^\| (\d+) \| `(\w+)` \|", reference,
                                                                        flags=re.M))
        self.assertEqual(rows, codes)


if __name__ == "__main__":
    unittest.main()
