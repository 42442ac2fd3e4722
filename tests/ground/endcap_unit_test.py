#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""The shipped systemd unit can start a secured end cap: the unit names a fixed user
(a DynamicUser= uid can own no key), the sysusers file makes that user, systemd
accepts the unit, and the end cap run as the owner of its enclave, as the docs say
to set it up, reads its 0600 key.pem (run as any other uid it cannot, and says so).

Usage: endcap_unit_test.py TENSEGRITY ENDCAP SOURCE_DIR
"""
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

TENSEGRITY, ENDCAP, SOURCE = sys.argv.pop(1), sys.argv.pop(1), pathlib.Path(sys.argv.pop(1))
UNIT = SOURCE / "firmware" / "endcap" / "endcap@.service"
SYSUSERS = SOURCE / "firmware" / "endcap" / "endcap.sysusers"
DOMAIN = "222"
# A uid no account here has, standing in for the unit's user: the test adds no user.
UID = 61234


def service_settings():
    """[Service] as (key, value) pairs, in order (systemd allows a key twice)."""
    section, out = None, []
    for line in UNIT.read_text().splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        if line.startswith("["):
            section = line
        elif section == "[Service]":
            key, _, value = line.partition("=")
            out.append((key.strip(), value.strip()))
    return out


class Unit(unittest.TestCase):
    def test_runs_as_the_fixed_user_the_sysusers_file_makes(self):
        settings = dict(service_settings())
        self.assertNotIn(settings.get("DynamicUser", "no").lower(), ("yes", "true", "1", "on"),
                         "a uid picked at each start cannot own the 0600 key.pem")
        user = settings.get("User")
        self.assertTrue(user, "no User=")
        lines = [ln.split() for ln in SYSUSERS.read_text().splitlines() if ln and not ln.startswith("#")]
        self.assertIn(["u", user], [ln[:2] for ln in lines])
        self.assertEqual(settings.get("Group", user), user)

    @unittest.skipUnless(shutil.which("systemd-analyze"), "no systemd-analyze")
    def test_systemd_accepts_the_unit(self):
        with tempfile.TemporaryDirectory() as d:
            unit = pathlib.Path(d) / "endcap@3.service"
            unit.write_text(UNIT.read_text().replace("/usr/local/bin/endcap", ENDCAP))
            done = subprocess.run(["systemd-analyze", "verify", "--man=no", str(unit)], capture_output=True,
                                  text=True)
            self.assertEqual(done.returncode, 0, done.stderr)
            self.assertEqual(done.stderr.strip(), "")

    @unittest.skipUnless(shutil.which("systemd-sysusers"), "no systemd-sysusers")
    def test_the_sysusers_file_makes_the_user(self):
        with tempfile.TemporaryDirectory() as root:
            os.makedirs(os.path.join(root, "etc"))
            subprocess.run(["systemd-sysusers", f"--root={root}", str(SYSUSERS)], check=True, capture_output=True)
            user = dict(service_settings())["User"]
            passwd = pathlib.Path(root, "etc", "passwd").read_text()
            self.assertTrue(any(ln.startswith(user + ":") for ln in passwd.splitlines()), passwd)


@unittest.skipUnless(os.geteuid() == 0 and shutil.which("setpriv"), "needs root (to run as another uid) and setpriv")
class KeyOwnership(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        os.chmod(self.dir, 0o755)  # the end cap's uid must reach its files
        self.keystore = os.path.join(self.dir, "keystore")
        subprocess.run([TENSEGRITY, "security", "init", self.keystore], check=True, capture_output=True)
        os.chmod(self.keystore, 0o755)
        self.storage = os.path.join(self.dir, "store")
        os.makedirs(self.storage)
        os.chown(self.storage, UID, UID)
        self.config = os.path.join(self.dir, "endcap-3.json")
        pathlib.Path(self.config).write_text(json.dumps({
            "format": "tensegrity-endcap/1", "bus": "udp:127.0.0.1:9",
            "nodes": {"drives": [1, 3], "load_cell": 2}, "spool": {"radius_m": 0.01, "counts_per_rev": 446464},
            "limits": {"min_rest_length_m": 0.6, "max_rest_length_m": 1.1, "speed_m_per_s": 0.2,
                       "cutoff_tension_n": 400, "hard_limit_tension_n": 500},
            "initial_rest_length_m": 0.95, "storage_dir": self.storage,
            "loop": {"period_ns": 4000000, "mode": "realtime"}, "dds_keystore": self.keystore}))
        os.chmod(self.config, 0o644)

    def tearDown(self):
        shutil.rmtree(self.dir)

    def run_endcap(self):
        """The end cap as the unit's user; (exit code or None if it ran on, its stderr)."""
        log = os.path.join(self.dir, "endcap.err")
        with open(log, "w") as err:
            p = subprocess.Popen(["setpriv", f"--reuid={UID}", f"--regid={UID}", "--clear-groups", ENDCAP, "--id",
                                  "3", "--config", self.config, "--domain", DOMAIN], stdout=subprocess.DEVNULL,
                                 stderr=err)
        # The key is read as the DDS participant is made, a fraction of a second in.
        deadline = time.monotonic() + 5
        while time.monotonic() < deadline and p.poll() is None:
            time.sleep(0.1)
        rc = p.poll()
        if rc is None:
            p.terminate()
            p.wait(10)
        return rc, pathlib.Path(log).read_text()

    def test_the_owner_of_the_enclave_reads_its_key(self):
        enclave = os.path.join(self.keystore, "enclaves", "tensegrity", "endcap_03")
        key = os.path.join(enclave, "key.pem")
        self.assertEqual(os.stat(key).st_mode & 0o777, 0o600)
        # As the unit comes: the key belongs to root, the end cap runs as another uid.
        rc, err = self.run_endcap()
        self.assertEqual(rc, 2, err)
        self.assertIn("key.pem: missing or unreadable", err)
        # As docs/guide/security.md sets the board up: the keystore belongs to the unit's user.
        for here, dirs, files in os.walk(self.keystore):
            for name in [here, *(os.path.join(here, f) for f in dirs + files)]:
                os.chown(name, UID, UID)
        rc, err = self.run_endcap()
        self.assertIsNone(rc, err)
        self.assertNotIn("unreadable", err)
        self.assertIn("DDS security: enclave", err)


if __name__ == "__main__":
    unittest.main()
