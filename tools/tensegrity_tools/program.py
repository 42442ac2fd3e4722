# SPDX-License-Identifier: Apache-2.0
"""The `tensegrity` program, found and run the same way by every tool.

Found: the tool's `--tensegrity BIN`, else $TENSEGRITY_BIN, else the release build
of this checkout, build/release/cli/tensegrity.

Run: `run(binary, args)` runs one command that prints JSON (`sim --json`, `evolve
--json`, `analyze --json`, `hil --json`) and returns the parsed document; a command
that fails raises RunError naming the command, its exit status and the end of its
stderr. RunError is a SystemExit, so a tool that does not catch it stops with that
message (also from a worker thread: a future re-raises it in the caller).
"""
import json
import os
import pathlib
import shlex
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]
ENV = "TENSEGRITY_BIN"
DEFAULT = ROOT / "build" / "release" / "cli" / "tensegrity"
OPTION_HELP = f"the tensegrity program (default: ${ENV}, else build/release/cli/tensegrity)"
BUILD_HINT = "cmake --preset release && cmake --build --preset release --target tensegrity"


class RunError(SystemExit):
    """A run of the program failed, or the program is not there."""

    def __init__(self, message):
        super().__init__(message)
        self.message = message

    def __str__(self):
        return self.message


def add_option(parser):
    """The one option that names the program: --tensegrity BIN."""
    parser.add_argument("--tensegrity", metavar="BIN", default=None, help=OPTION_HELP)


def find(given=None, environ=None):
    """The program's path: `given` (a tool's --tensegrity), else $TENSEGRITY_BIN, else
    build/release/cli/tensegrity. Raises RunError when that is not an executable file,
    naming where the path came from."""
    environ = os.environ if environ is None else environ
    if given:
        path, source = pathlib.Path(given), f"--tensegrity {given}"
    elif environ.get(ENV):
        path, source = pathlib.Path(environ[ENV]), f"${ENV}={environ[ENV]}"
    else:
        path, source = DEFAULT, f"the default {DEFAULT}"
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise RunError(f"{source}: not an executable tensegrity program (build it: {BUILD_HINT}; "
                       f"or give --tensegrity BIN or ${ENV})")
    return str(path)


def command_text(cmd):
    return " ".join(shlex.quote(str(c)) for c in cmd)


def failure(cmd, returncode, stdout, stderr):
    """The message of a failed run: the JSON's own `error` when the program printed one."""
    why = (stderr or "").strip()[-2000:]
    try:
        doc = json.loads(stdout or "")
        if isinstance(doc, dict) and doc.get("error"):
            why = f"{doc['error']}" + (f" ({why})" if why else "")
    except json.JSONDecodeError:
        pass
    return f"{command_text(cmd)}: exit {returncode}: {why or 'no message'}"


def command(binary, args, nice=None):
    """The argv of one run: the program and its arguments, under `nice -n N` if given."""
    cmd = [str(binary)] + [str(a) for a in args]
    return (["nice", "-n", str(nice)] + cmd) if nice is not None else cmd


def run(binary, args, nice=None, cwd=None, stderr_path=None):
    """Runs `binary args` (which must print one JSON document) and returns it parsed.
    stderr goes to `stderr_path` when given, else it is kept for the error message."""
    cmd = command(binary, args, nice)
    if stderr_path is not None:
        with open(stderr_path, "w") as err:
            done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=err, text=True, cwd=cwd)
        stderr = f"see {stderr_path}"
    else:
        done = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd)
        stderr = done.stderr
    if done.returncode != 0:
        raise RunError(failure(cmd, done.returncode, done.stdout, stderr))
    try:
        return json.loads(done.stdout)
    except json.JSONDecodeError as e:
        raise RunError(f"{command_text(cmd)}: no JSON on stdout ({e})") from None


def text(binary, args):
    """Runs `binary args` and returns what it printed (e.g. `--help`)."""
    cmd = command(binary, args)
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RunError(failure(cmd, done.returncode, done.stdout, done.stderr))
    return done.stdout


def sim(binary, policy, robot=None, options=(), nice=None):
    """One episode, `tensegrity sim --policy POLICY [--robot ROBOT] OPTIONS --json`: its
    summary (distance_m, feasible, tensions, ...)."""
    args = ["sim", "--policy", policy] + (["--robot", robot] if robot is not None else []) + list(options)
    return run(binary, args + ["--json"], nice=nice)
