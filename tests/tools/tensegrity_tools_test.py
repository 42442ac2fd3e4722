#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""tools/tensegrity_tools (finding and running the program, reading run records),
tools/plot_run.py on a real `sim --telemetry` record and on HIL records of both
column spellings, every script's --help and its usage in docs/reference/tools.md, and
that no script imports another.

Usage: tensegrity_tools_test.py TOOLS_DIR TENSEGRITY
"""
import ast
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest

TOOLS, TENSEGRITY = (pathlib.Path(x) for x in sys.argv[1:3])
del sys.argv[1:3]
sys.path.insert(0, str(TOOLS))
from tensegrity_tools import program, runs  # noqa: E402


def script(path, text):
    path.write_text("#!/usr/bin/python3\n" + text)
    path.chmod(0o755)
    return path


def hil_record(path, legacy, rows=((0.0, 0.0), (0.5, 3.0)), cut=False):
    """A two-cable, one-node HIL record: (time, centre x) per row; tensions 100 + cable."""
    names = [(f"{q}_{m}" if legacy else f"cable{m}_{q}") for q in ("rest_length_m", "tension_n") for m in range(2)]
    lines = [",".join(["time_s", "centre_x_m", "centre_y_m", "centre_z_m"] + names + ["node0_x_m", "node0_y_m",
                                                                                          "node0_z_m"])]
    for t, x in rows:
        lines.append(f"{t},{x},0,0.5,0.9,0.9,100,101,{x},0,0.5")
    if cut:
        lines.append("1.0,4.0,0")
    path.write_text("\n".join(lines) + "\n")
    return path


class Find(unittest.TestCase):
    def test_the_option_then_the_environment_then_the_release_build(self):
        with tempfile.TemporaryDirectory() as d:
            given = script(pathlib.Path(d) / "given", "")
            from_env = script(pathlib.Path(d) / "env", "")
            self.assertEqual(program.find(str(given), {program.ENV: str(from_env)}), str(given))
            self.assertEqual(program.find(None, {program.ENV: str(from_env)}), str(from_env))
            if not program.DEFAULT.exists():
                with self.assertRaisesRegex(program.RunError, "build/release/cli/tensegrity"):
                    program.find(None, {})
            else:
                self.assertEqual(program.find(None, {}), str(program.DEFAULT))

    def test_a_missing_program_is_named_with_where_its_path_came_from(self):
        with self.assertRaisesRegex(program.RunError, "--tensegrity /nowhere/tensegrity: not an executable"):
            program.find("/nowhere/tensegrity", {})
        with self.assertRaisesRegex(program.RunError, r"\$TENSEGRITY_BIN=/nowhere: not an executable"):
            program.find(None, {program.ENV: "/nowhere"})


class Run(unittest.TestCase):
    def test_json_is_returned_and_a_failure_names_command_status_and_reason(self):
        with tempfile.TemporaryDirectory() as d:
            good = script(pathlib.Path(d) / "good", 'import json, sys\nprint(json.dumps({"argv": sys.argv[1:]}))\n')
            self.assertEqual(program.sim(good, "p.json", "r.json", ["--start", "settled"]),
                             {"argv": ["sim", "--policy", "p.json", "--robot", "r.json", "--start", "settled",
                                       "--json"]})
            bad = script(pathlib.Path(d) / "bad", 'import sys\nprint("no such policy", file=sys.stderr)\nsys.exit(3)\n')
            with self.assertRaisesRegex(program.RunError, "bad sim --policy p.json --json: exit 3: no such policy"):
                program.sim(bad, "p.json")
            said = script(pathlib.Path(d) / "said", 'import sys\nprint(\'{"ok": false, "error": "boot timeout"}\')\n'
                                                   'sys.exit(1)\n')
            with self.assertRaisesRegex(program.RunError, "exit 1: boot timeout"):
                program.run(said, ["hil", "--json"])
            mute = script(pathlib.Path(d) / "mute", 'print("not json")\n')
            with self.assertRaisesRegex(program.RunError, "no JSON on stdout"):
                program.run(mute, ["sim"])


class Records(unittest.TestCase):
    def test_both_hil_spellings_read_alike(self):
        with tempfile.TemporaryDirectory() as d:
            now = runs.read_record(hil_record(pathlib.Path(d) / "now.csv", legacy=False))
            old = runs.read_record(hil_record(pathlib.Path(d) / "old.csv", legacy=True))
            for r in (now, old):
                self.assertEqual(r.cables("tension_n"), [[100.0, 101.0], [100.0, 101.0]])
                self.assertEqual(r.cable_count("rest_length_m"), 2)
                self.assertEqual(r.distance_m(), [0.0, 3.0])

    def test_a_cut_last_line_is_dropped_and_damage_elsewhere_is_named(self):
        with tempfile.TemporaryDirectory() as d:
            cut = runs.read_record(hil_record(pathlib.Path(d) / "cut.csv", legacy=False, cut=True))
            self.assertEqual(cut.times_s(), [0.0, 0.5])
            path = hil_record(pathlib.Path(d) / "mid.csv", legacy=False, cut=True)
            path.write_text(path.read_text() + "2.0,5.0,0,0.5,0.9,0.9,100,101,5.0,0,0.5\n")
            with self.assertRaisesRegex(runs.RecordError, "mid.csv, line 4: cells missing"):
                runs.read_record(path)
            path.write_text(path.read_text().replace("0.5,3.0,", "0.5,x,"))
            with self.assertRaisesRegex(runs.RecordError, "mid.csv, line 3: centre_x_m 'x' is not a number"):
                runs.read_record(path)

    def test_the_centre_of_a_simulator_record_is_the_mean_of_its_end_caps(self):
        with tempfile.TemporaryDirectory() as d:
            path = pathlib.Path(d) / "sim.csv"
            path.write_text("time_s,node0_x_m,node0_y_m,node0_z_m,node1_x_m,node1_y_m,node1_z_m,cable0_tension_n\n"
                            "0,0,0,0,2,0,0,5\n1,3,4,0,5,4,0,6\n")
            r = runs.read_record(path)
            self.assertEqual(r.centre_m(), [(1.0, 0.0, 0.0), (4.0, 4.0, 0.0)])
            self.assertEqual(r.distance_m(), [0.0, 5.0])
            with self.assertRaisesRegex(runs.RecordError, "no column cable0_length_m"):
                r.cables("length_m")

    def test_a_learning_curve_is_read_and_a_bad_cell_named(self):
        with tempfile.TemporaryDirectory() as d:
            path = pathlib.Path(d) / "curve.csv"
            path.write_text("generation,episodes,best_so_far_m,mean_score_m\n1,50,4.5,2\n2,100,lost,3\n")
            with self.assertRaisesRegex(runs.RecordError, "curve.csv, line 3: best_so_far_m 'lost' is not a number"):
                runs.read_curve(path)
            path.write_text("generation,episodes\n1,50\n")
            with self.assertRaisesRegex(runs.RecordError, "no column best_so_far_m, mean_score_m"):
                runs.read_curve(path)
            path.write_text("evaluations,best_m\n18,4.5\n36\n")
            self.assertRaisesRegex(runs.RecordError, "line 3: fewer cells than the header's 2", runs.read_table, path)
            path.write_text("evaluations,best_m\n18,4.5\n36,5,7\n")
            self.assertRaisesRegex(runs.RecordError, "line 3: more cells", runs.read_table, path)
            path.write_text("evaluations,best_m\n18,4.5\n36,5\n")
            self.assertEqual(runs.read_table(path, ("best_m",)), [{"evaluations": 18.0, "best_m": 4.5},
                                                                {"evaluations": 36.0, "best_m": 5.0}])


class PlotRun(unittest.TestCase):
    def plot(self, record, png):
        return subprocess.run(["/usr/bin/python3", str(TOOLS / "plot_run.py"), str(record), str(png), "--every", "1"],
                              capture_output=True, text=True)

    def test_a_simulator_record_and_both_hil_spellings_are_plotted(self):
        with tempfile.TemporaryDirectory() as d:
            d = pathlib.Path(d)
            telemetry = d / "sim.csv"
            subprocess.run([str(TENSEGRITY), "sim", "--duration", "0.5", "--telemetry", str(telemetry),
                            "--telemetry-every", "50"], capture_output=True, check=True)
            for record in (telemetry, hil_record(d / "now.csv", False), hil_record(d / "old.csv", True)):
                done = self.plot(record, d / (record.stem + ".png"))
                self.assertEqual(done.returncode, 0, done.stderr)
                self.assertGreater((d / (record.stem + ".png")).stat().st_size, 0)

    def test_a_file_that_is_not_a_run_record_is_named(self):
        with tempfile.TemporaryDirectory() as d:
            other = pathlib.Path(d) / "curve.csv"
            other.write_text("generation,episodes\n1,50\n")
            done = self.plot(other, pathlib.Path(d) / "x.png")
            self.assertEqual(done.returncode, 2)
            self.assertIn("curve.csv, line 1: no column time_s", done.stderr)


def imported_modules(path):
    """The top-level names of the modules a Python file imports (relative ones as '.')."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            names.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            names.add("." if node.level else node.module.split(".")[0])
    return names


class Imports(unittest.TestCase):
    def test_no_script_imports_another_script_and_the_package_imports_none(self):
        scripts = {p.stem for p in TOOLS.glob("*.py")}
        self.assertIn("arm", scripts)
        for path in sorted(TOOLS.glob("*.py")) + sorted((TOOLS / "tensegrity_tools").glob("*.py")):
            self.assertEqual(imported_modules(path) & scripts, set(), f"{path.name} imports a script of tools/")


class Help(unittest.TestCase):
    def test_every_script_answers_help(self):
        scripts = sorted(TOOLS.glob("*.py"))
        self.assertGreater(len(scripts), 10)
        for path in scripts:
            done = subprocess.run(["/usr/bin/python3", str(path), "--help"], capture_output=True, text=True,
                                  env=dict(os.environ, TENSEGRITY_BIN="/nowhere"))
            self.assertEqual(done.returncode, 0, f"{path.name}: {done.stderr}")
            self.assertIn("usage", done.stdout.lower(), path.name)

    def test_the_reference_shows_each_scripts_usage_as_it_prints_it(self):
        reference = (TOOLS.parent / "docs" / "reference" / "tools.md").read_text()
        blocks = re.findall(r"```text\n(tools/(\w+)\.py .*?)\n```", reference, flags=re.S)
        self.assertGreater(len(blocks), 5)
        for block, name in blocks:
            done = subprocess.run(["/usr/bin/python3", str(TOOLS / f"{name}.py"), "--help"], capture_output=True,
                                  text=True, env=dict(os.environ, COLUMNS="80"))
            usage = done.stdout.split("\n\n")[0]
            # argparse indents its continuation lines under "usage: NAME.py"; the page
            # under "tools/NAME.py", one column less.
            expected = "\n".join(line[1:] if line.startswith(" ") else "tools/" + line[len("usage: "):]
                                  for line in usage.split("\n"))
            self.assertEqual(block, expected, f"docs/reference/tools.md, {name}.py: not its --help's usage")


if __name__ == "__main__":
    unittest.main()
