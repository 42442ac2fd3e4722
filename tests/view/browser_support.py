# SPDX-License-Identifier: Apache-2.0
"""Helpers of the view's browser test: headless Chromium through Debian's
chromium-driver, processes that are always stopped, free ports."""
import os
import signal
import socket
import subprocess
import time
import urllib.error
import urllib.request

from selenium import webdriver
from selenium.webdriver.chrome.service import Service


def chromium():
    """Headless Chromium rendering WebGL in software (SwiftShader through ANGLE),
    as on a machine without a GPU."""
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist", "--window-size=1280,800",
                "--disable-background-timer-throttling", "--disable-renderer-backgrounding"):
        options.add_argument(arg)
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Process:
    """A child process, stopped (SIGTERM, then SIGKILL) when the block ends."""

    def __init__(self, args, log_path):
        self.log = open(log_path, "w")
        self.args = args
        self.proc = subprocess.Popen(args, stdout=self.log, stderr=subprocess.STDOUT)

    def stop(self, timeout=10):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.log.close()
        return self.proc.returncode

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()


def http(url, method="GET", data=None, timeout=5):
    """(status, body) of one request; HTTP errors are answers too."""
    req = urllib.request.Request(url, method=method, data=data)
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def wait_for(what, predicate, timeout, interval=0.1):
    """predicate()'s first truthy value; AssertionError naming `what` after timeout."""
    end = time.monotonic() + timeout
    last = None
    while time.monotonic() < end:
        try:
            last = predicate()
            if last:
                return last
        except AssertionError:
            raise  # the predicate's own verdict (a process that died)
        except Exception as e:  # the page not there yet
            last = e
        time.sleep(interval)
    raise AssertionError(f"timed out after {timeout} s waiting for {what} (last: {last!r})")


def wait_for_server(port, proc, timeout=30):
    def up():
        if proc.proc.poll() is not None:
            raise AssertionError(f"{proc.args[0]} exited with {proc.proc.returncode}, see {proc.log.name}")
        return http(f"http://127.0.0.1:{port}/api/mode", timeout=1)[0] == 200
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        try:
            if up():
                return
        except (OSError, urllib.error.URLError):
            pass
        time.sleep(0.1)
    raise AssertionError(f"view on port {port} did not come up in {timeout} s")


def view_state(driver, expr):
    return driver.execute_script(f"return window.tensegrityView ? window.tensegrityView.{expr} : null")


def check_scene(driver, label):
    """The canvas is not blank and the scene holds 12 end caps, 24 cables, 6 struts."""
    counts = wait_for(f"{label}: scene", lambda: view_state(driver, "counts()"), 30)
    assert counts == {"endcaps": 12, "cables": 24, "struts": 6}, f"{label}: scene holds {counts}"
    pixels = view_state(driver, "sampleCanvas()")
    total = pixels["width"] * pixels["height"]
    assert pixels["nonBackground"] > 0.05 * total and pixels["distinctColours"] > 20, f"{label}: canvas blank? {pixels}"
    print(f"{label}: scene {counts}, canvas {pixels['width']}x{pixels['height']}, "
          f"{100.0 * pixels['nonBackground'] / total:.0f} % drawn, {pixels['distinctColours']} colours")


def screenshot(driver, directory, name):
    if directory:
        os.makedirs(directory, exist_ok=True)
        path = os.path.join(directory, name)
        driver.save_screenshot(path)
        print(f"screenshot {path}")
