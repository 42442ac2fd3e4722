#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""`tensegrity view` in a real browser (headless Chromium, software WebGL): each
mode loads, draws (pixels read back), holds 12 end caps and 24 cables; the replay's
slider moves time and the robot; the live page follows a HIL run (real time: see test_live), says
"disconnected" when its server stops and reconnects when it is back; the view
refuses every method but GET. Prints the replay's open time and frame rate and the
live latency (measured here, not asserted: docs/guide/view.md)."""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

from selenium.webdriver.common.by import By
from selenium.common.exceptions import TimeoutException
from selenium.webdriver.common.keys import Keys

from browser_support import (Process, check_scene, chromium, free_port, http, screenshot, view_state, wait_for,
                             wait_for_server)

NTRT_ROBOT = "robots/superball-ntrt2014.json"
# The replay (and the README's picture of it) is the main job's: scripts/run.sh's gait.
ROBOT = "robots/superball-paper.json"
POLICY = "policies/superball-paper-t4-n5.json"


def check_read_only(port, paths):
    for path in paths:
        for method in ("POST", "PUT", "DELETE", "PATCH"):
            status, _ = http(f"http://127.0.0.1:{port}{path}", method=method, data=b'{"kind":2}')
            assert status == 405, f"{method} {path} answered {status}, not 405"
    print(f"read-only: POST/PUT/DELETE/PATCH refused (405) on {', '.join(paths)}")


def check_bad_csv(args, good_csv, tmp):
    lines = open(good_csv).read().splitlines()
    fields = lines[4].split(",")
    fields[3] = "abc"
    lines[4] = ",".join(fields)
    bad = os.path.join(tmp, "bad.csv")
    with open(bad, "w") as f:
        f.write("\n".join(lines) + "\n")
    r = subprocess.run([args.tensegrity, "view", bad, "--robot", ROBOT, "--port", "0"], capture_output=True,
                       text=True, timeout=60)
    name = lines[0].split(",")[3]
    assert r.returncode == 2 and f"bad.csv:5:4 ({name})" in r.stderr, f"bad CSV: {r.returncode} {r.stderr!r}"
    print(f"bad CSV refused: {r.stderr.strip()}")


def press(driver, element, key, times=1):
    for _ in range(times):
        element.send_keys(key)


def test_replay(args, driver, tmp):
    csv = os.path.join(tmp, "run.csv")
    subprocess.run([args.tensegrity, "sim", "--policy", POLICY, "--duration", "60", "--telemetry", csv,
                    "--telemetry-every", "10"], check=True, stdout=subprocess.DEVNULL, timeout=600)
    check_bad_csv(args, csv, tmp)
    port = free_port()
    with Process([args.tensegrity, "view", csv, "--robot", ROBOT, "--port", str(port)],
                 os.path.join(tmp, "view.log")) as view:
        wait_for_server(port, view)
        check_read_only(port, ["/", "/api/replay", "/api/mode"])
        started = time.monotonic()
        driver.get(f"http://127.0.0.1:{port}/")
        wait_for("first frame", lambda: view_state(driver, "stats().openMs") is not None, 30, interval=0.02)
        open_s = time.monotonic() - started
        open_ms = view_state(driver, "stats().openMs")
        print(f"MEASURE replay_open_s {open_s:.2f} (page's own: {open_ms / 1000:.2f} s from navigation start)")
        check_scene(driver, "replay")
        slider = driver.find_element(By.ID, "slider")
        t0, c0 = view_state(driver, "time()"), view_state(driver, "robotCentre()")
        press(driver, slider, Keys.END)
        t1, c1 = view_state(driver, "time()"), view_state(driver, "robotCentre()")
        moved = ((c1[0] - c0[0]) ** 2 + (c1[1] - c0[1]) ** 2) ** 0.5
        assert t1 > t0 + 50 and moved > 1.0, f"slider to the end: time {t0} -> {t1}, robot moved {moved:.2f} m"
        press(driver, slider, Keys.HOME)
        assert view_state(driver, "time()") == t0, "slider back to the start"
        print(f"slider: time {t0:.2f} -> {t1:.2f} s, the robot moved {moved:.2f} m with it")
        driver.find_element(By.ID, "play").click()
        before = view_state(driver, "stats().framesDrawn")
        time.sleep(6)
        fps_page = view_state(driver, "stats().fps")
        drawn = view_state(driver, "stats().framesDrawn") - before
        playing_t = view_state(driver, "time()")
        assert view_state(driver, "playing()") and playing_t > 3, f"playing: time {playing_t}"
        print(f"MEASURE replay_fps {fps_page:.1f} (last second; {drawn / 6:.1f} over 6 s)")
        press(driver, slider, Keys.PAGE_UP, 20)
        driver.find_element(By.ID, "play").click()
        screenshot(driver, args.screenshots, "replay.png")


def hil_domain(log_path):
    text = open(log_path).read()
    m = re.search(r"DDS domain (\d+)\) at http://127\.0\.0\.1:(\d+)/", text)
    return (int(m.group(1)), int(m.group(2))) if m else None


def test_live(args, driver, tmp):
    port = free_port()
    hil_log = os.path.join(tmp, "hil.log")
    # A lockstep run, as the issue asks, at real-time speed (`hil --view` sets
    # --speed 1): flat out, its SCHED_FIFO threads held both cores and the page's
    # scripts timed out; in real time twelve end caps' own 1 kHz
    # loops left their DDS threads so little that discovery or time sync missed
    # 30 s in CI. The page opens once all 12 end caps play (--view-wait 0, then the
    # view's own status), so that the software-rendering browser does not compete
    # with the run's DDS discovery.
    # --insecure: the page's own DDS participant does not rejoin a stalled DDS
    # Security handshake yet (docs/guide/security.md); what is tested here is the page.
    with Process([args.tensegrity, "hil", "--insecure", "--mode", args.hil_mode, "--duration", "300", "--endcap", args.endcap,
                  "--barrier-timeout", "30", "--view", "--view-port", str(port), "--view-wait", "0"], hil_log) as hil:
        domain, _ = wait_for("hil --view's page", lambda: hil_domain(hil_log), 60)
        wait_for_server(port, hil)

        def all_playing():
            assert hil.proc.poll() is None, f"the HIL run ended early: {open(hil_log).read()[-2000:]}"
            code, body = http(f"http://127.0.0.1:{port}/api/live/status")
            ends = json.loads(body)["endcaps"] if code == 200 else []
            return len(ends) == 12 and all(e["seen"] and e["state"] == "running" for e in ends)
        wait_for("12 end caps playing", all_playing, 120, interval=0.5)
        driver.get(f"http://127.0.0.1:{port}/")
        def streaming():
            assert hil.proc.poll() is None, f"the HIL run ended early: {open(hil_log).read()[-2000:]}"
            return view_state(driver, "live().endcapsSeen") == 12 and view_state(driver, "live().samples") > 200
        wait_for("12 end caps streaming", streaming, 120)
        check_scene(driver, "live")
        check_read_only(port, ["/", "/api/live/events", "/api/live/status", "/api/clock"])
        time.sleep(5)
        latency = view_state(driver, "live().latency")
        own = view_state(driver, "live().viewLatency")
        print(f"MEASURE live_latency_ms median {latency['p50']:.1f} p95 {latency['p95']:.1f} "
              f"max {latency['max']:.1f} over {latency['count']} samples ({args.hil_mode} HIL, sample to page)")
        print(f"MEASURE live_view_latency_ms median {own['p50']:.1f} p95 {own['p95']:.1f} max {own['max']:.1f} "
              f"over {own['count']} samples (the view's DDS receive to the page)")
        for name in ("latencyRecent", "viewLatencyRecent"):
            try:
                r = view_state(driver, f"live().{name}")
            except TimeoutException:  # a measurement, not a check: a starved page may not answer
                print(f"MEASURE live_{name} not measured (the page did not answer in time)")
                continue
            if r["count"]:
                print(f"MEASURE live_{name} median {r['p50']:.1f} p95 {r['p95']:.1f} max {r['max']:.1f} "
                      f"over {r['count']} samples (the last 5 s)")
        assert latency["count"] > 100, f"latency samples {latency}"
        screenshot(driver, args.screenshots, "live.png")
        # A second view of the same run, stopped and started again under the page.
        port2 = free_port()
        cmd = [args.tensegrity, "view", "--live", "--insecure", "--domain", str(domain), "--port", str(port2)]
        view = Process(cmd, os.path.join(tmp, "view1.log"))
        wait_for_server(port2, view)
        driver.get(f"http://127.0.0.1:{port2}/")
        wait_for("second view streaming", lambda: view_state(driver, "live().samples") > 50, 60)
        view.stop()
        wait_for("'disconnected'", lambda: driver.find_element(By.ID, "status").text == "disconnected", 15)
        samples = view_state(driver, "live().samples")
        print("server stopped: the page says disconnected")
        with Process(cmd, os.path.join(tmp, "view2.log")) as again:
            wait_for_server(port2, again)
            wait_for("reconnected", lambda: driver.find_element(By.ID, "status").text == "connected"
                     and view_state(driver, "live().samples") > samples + 50, 30)
            print(f"server back: reconnected ({view_state(driver, 'live().connects')} connections), streaming again")
        assert hil.proc.poll() is None, "the HIL run ended before the checks (see hil.log)"


def test_evolve(args, driver, tmp):
    run = os.path.join(tmp, "evolution")
    cmd = [args.tensegrity, "evolve", "--robot", NTRT_ROBOT, "--period", "4", "--complexity", "3", "--method",
           "historical", "--episodes", "24", "--teams", "6", "--population", "4", "--replace", "1",
           "--duration", "4", "--seed", "1", "--threads", "1", "--checkpoint", run, "--out",
           os.path.join(tmp, "evolved.json"), "--log", os.path.join(tmp, "curve.csv")]
    os.makedirs(run)
    port = free_port()
    with Process(cmd, os.path.join(tmp, "evolve.log")) as evolve, \
            Process([args.tensegrity, "view", "--evolve", run, "--port", str(port)],
                    os.path.join(tmp, "view.log")) as view:
        wait_for_server(port, view)
        driver.get(f"http://127.0.0.1:{port}/")
        wait_for("a generation on the curve", lambda: view_state(driver, "evolve().generations") >= 1, 120)
        wait_for("the best team's replay", lambda: view_state(driver, "frame()") is not None, 120)
        check_scene(driver, "evolve")
        assert evolve.proc.wait(300) == 0, "the evolution failed (evolve.log)"
        wait_for("the finished curve", lambda: view_state(driver, "evolve().state") == "finished"
                 and view_state(driver, "evolve().generations") == 4, 30)
        slider = driver.find_element(By.ID, "slider")
        t0 = view_state(driver, "time()")
        slider.send_keys(Keys.END)
        assert view_state(driver, "time()") > t0 + 3, "evolve: the slider moves the best team's replay"
        slider.send_keys(Keys.PAGE_UP)
        print(f"evolve: 4 generations followed to 'finished', best team replayed "
              f"({view_state(driver, 'evolve().replayVersion')} replays)")
        check_read_only(port, ["/api/evolve/curve", "/api/replay"])
        screenshot(driver, args.screenshots, "evolve.png")


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("mode", choices=["replay", "live", "evolve"])
    p.add_argument("--tensegrity", required=True)
    p.add_argument("--endcap")
    p.add_argument("--hil-mode", default="lockstep", choices=["realtime", "lockstep"])
    p.add_argument("--source-dir", required=True)
    p.add_argument("--screenshots", help="directory for PNG screenshots (docs/view to update the docs)")
    args = p.parse_args()
    os.chdir(args.source_dir)
    with tempfile.TemporaryDirectory(prefix="view-test-") as tmp:
        driver = chromium()
        try:
            {"replay": test_replay, "live": test_live, "evolve": test_evolve}[args.mode](args, driver, tmp)
        except Exception:
            for name in sorted(os.listdir(tmp)):
                if name.endswith(".log"):
                    print(f"--- {name}\n{open(os.path.join(tmp, name)).read()[-3000:]}")
            raise
        finally:
            driver.quit()
    print(f"view {args.mode}: ok")


if __name__ == "__main__":
    sys.exit(main())
