#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""The shipped console unit (cli/tensegrity-console@.service) does what the robot
guide says: systemd accepts it as a user unit that keeps one console running, and
its command line run as systemd runs it (no terminal, stdin /dev/null, the user's
runtime folder and default keystore) keeps serving its socket, so that `tensegrity
estop` from another shell of that user goes through it; SIGTERM ends it in time.

Usage: console_unit_test.py TENSEGRITY SOURCE_DIR
"""
import os
import pathlib
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

TENSEGRITY, SOURCE = sys.argv.pop(1), pathlib.Path(sys.argv.pop(1))
UNIT = SOURCE / "cli" / "tensegrity-console@.service"
DOMAIN = "209"


def settings(section):
    """The section's (key, value) pairs, in order."""
    current, out = None, []
    for line in UNIT.read_text().splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith("["):
            current = line
        elif current == section:
            key, _, value = line.partition("=")
            out.append((key.strip(), value.strip()))
    return dict(out)


def command_line(domain):
    """ExecStart= as systemd expands it for instance `domain`, with this build's program."""
    words = shlex.split(settings("[Service]")["ExecStart"].replace("%i", domain))
    assert words[0] == "/usr/local/bin/tensegrity", words[0]
    return [TENSEGRITY] + words[1:]


class UnitFile(unittest.TestCase):
    def test_a_user_unit_that_keeps_one_console_running(self):
        service = settings("[Service]")
        self.assertNotIn("User", service, "a user unit runs as its user; User= belongs to system units")
        self.assertEqual(service.get("Restart"), "always")
        self.assertEqual(settings("[Install]").get("WantedBy"), "default.target")
        words = command_line("42")
        self.assertEqual(words[1:], ["console", "--domain", "42"])
        # Stopping must leave an emergency stop in flight time to land (the console's
        # default timeout is 30 s).
        self.assertGreater(float(service["TimeoutStopSec"]), 30)

    @unittest.skipUnless(shutil.which("systemd-analyze"), "no systemd-analyze")
    def test_systemd_accepts_the_unit(self):
        with tempfile.TemporaryDirectory() as d:
            unit = pathlib.Path(d) / "tensegrity-console@42.service"
            unit.write_text(UNIT.read_text().replace("/usr/local/bin/tensegrity", TENSEGRITY))
            done = subprocess.run(["systemd-analyze", "verify", "--man=no", str(unit)], capture_output=True,
                                  text=True)
            complaints = [ln for ln in done.stderr.splitlines() if unit.name in ln or "ExecStart" in ln]
            self.assertEqual(complaints, [], done.stderr)


class RunAsTheUnitDoes(unittest.TestCase):
    def setUp(self):
        self.home = tempfile.TemporaryDirectory()
        home = pathlib.Path(self.home.name)
        runtime = home / "run"
        runtime.mkdir(mode=0o700)
        self.env = {k: v for k, v in os.environ.items() if not k.startswith(("TENSEGRITY_", "XDG_"))}
        self.env.update(HOME=str(home), XDG_RUNTIME_DIR=str(runtime))
        subprocess.run([TENSEGRITY, "security", "init"], env=self.env, check=True, capture_output=True)
        self.socket = runtime / "tensegrity" / f"console-{DOMAIN}.sock"

    def tearDown(self):
        self.home.cleanup()

    def test_estop_from_another_shell_goes_through_it(self):
        console = subprocess.Popen(command_line(DOMAIN), env=self.env, stdin=subprocess.DEVNULL,
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            deadline = time.monotonic() + 30
            while not self.socket.exists() and console.poll() is None and time.monotonic() < deadline:
                time.sleep(0.1)
            self.assertIsNone(console.poll(), "the console ended with stdin at /dev/null")
            self.assertTrue(self.socket.exists(), f"no socket at {self.socket}")
            # stdin's end of file must not end it: a unit's stdin is /dev/null.
            time.sleep(1.0)
            self.assertIsNone(console.poll(), "the console ended once stdin was at its end")
            estop = subprocess.run([TENSEGRITY, "estop", "--domain", DOMAIN, "--endcaps", "0", "--timeout", "0.5"],
                                   env=self.env, capture_output=True, text=True, timeout=30)
            self.assertIn(f"sent by the console at {self.socket}", estop.stderr)
            # No end cap runs here: the console sent it and says end cap 0 never acked.
            self.assertEqual(estop.returncode, 1, estop.stderr)
            console.send_signal(signal.SIGTERM)
            out, err = console.communicate(timeout=float(settings("[Service]")["TimeoutStopSec"]))
            self.assertEqual(console.returncode, 0, err)
        finally:
            if console.poll() is None:
                console.kill()
                console.communicate()


if __name__ == "__main__":
    unittest.main()
