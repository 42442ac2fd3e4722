#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Regenerate the paper's learning figures (6-9) on this model.

Runs `tensegrity evolve` for every (method, period, complexity, seed) the
figures need, several at a time, and writes per figure a CSV and a PNG:

  fig6_methods.csv/png      historical vs leniency vs average (t = 4 s, n = 5):
                            best-so-far and mean team score per generation
  fig7_learning.csv/png     historical, t = 4 s, n = 5: best-so-far and the
                            infeasible rate per generation
  fig8_period.csv/png       n = 5, t = 2..8 s: the best team of each run
  fig9_complexity.csv/png   t = 4 s, n = 2..8: the best team of each run
  summary.json              the numbers above, aggregated over seeds

Error bars are the standard deviation over seeds. A run is identified by its
parameters; it checkpoints every generation into OUT/runs/<id>/, so the script
can be stopped and started again: finished runs are reused, unfinished ones
resume where they stopped. Runs shared by several figures (historical, t = 4 s,
n = 5) are done once. The figures draw every finished run in OUT/runs made with
the same step and episode length, so a sweep can be run in parts (a few points or
seeds at a time) without a later part dropping the earlier ones from the plots.

Examples:
  tools/experiments.py --out out/experiments                 # the paper's budget
  tools/experiments.py --out out/quick --seeds 2 --episodes 1000 --sweep-episodes 500
  tools/experiments.py --out out/experiments --plot-only     # redraw from the runs
"""
import argparse
import concurrent.futures
import json
import os
import pathlib
import sys
import threading
import time

from tensegrity_tools import experiment_figures, program, runs
from tensegrity_tools.experiment_pins import pin_robot, pin_settings


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default="out/experiments", help="output directory (default: %(default)s)")
    program.add_option(p)
    p.add_argument("--robot", default=str(program.ROOT / "robots/superball-paper.json"),
                   help="robot description (default: the default robot, the paper's simulated SUPERball)")
    p.add_argument("--seeds", type=int, default=5, help="seeds per configuration, 1..N (default: %(default)s)")
    p.add_argument("--method-seeds", type=int, default=None,
                   help="seeds for figure 6's leniency and average baselines (default: --seeds)")
    p.add_argument("--sweep-seeds", type=int, default=None,
                   help="seeds per point of the sweeps, figures 8 and 9 (default: --seeds)")
    p.add_argument("--first-seed", type=int, default=1, help="first seed (default: %(default)s)")
    p.add_argument("--episodes", type=int, default=5000,
                   help="episodes per run for figures 6 and 7 (default: %(default)s)")
    p.add_argument("--sweep-episodes", type=int, default=None,
                   help="episodes per run for the sweeps, figures 8 and 9 (default: --episodes)")
    p.add_argument("--periods", default="2,3,4,5,6,7,8", help="figure 8 periods, s (default: %(default)s)")
    p.add_argument("--complexities", default="2,3,4,5,6,7,8", help="figure 9 complexities (default: %(default)s)")
    p.add_argument("--figures", default="6,7,8,9", help="which figures (default: %(default)s)")
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1,
                   help="evolutions at once, one thread each (default: the cores, %(default)s)")
    p.add_argument("--duration", type=float, default=60.0,
                   help="episode length, s (default: the paper's %(default)s; shorter only for smoke tests)")
    p.add_argument("--sigma", type=float, default=None,
                   help="mutation step, m (default: tensegrity evolve's schedule, docs/guide/evolve.md)")
    p.add_argument("--sigma-final", type=float, default=None,
                   help="anneal the step to this, m (default: no annealing once --sigma is given)")
    p.add_argument("--anneal-episodes", type=int, default=0,
                   help="episodes over which the step anneals (default: %(default)s)")
    p.add_argument("--plot-only", action="store_true", help="do not run anything; plot what is there")
    a = p.parse_args()
    a.sweep_episodes = a.sweep_episodes or a.episodes
    if not pathlib.Path(a.robot).is_file():
        p.error(f"--robot {a.robot}: no such file")
    if (a.sigma_final is None) != (a.anneal_episodes == 0):
        p.error("--sigma-final and --anneal-episodes go together")
    # Runs with another mutation than the default get their own directories.
    if a.sigma_final is not None and a.sigma is None:
        p.error("--sigma-final needs --sigma (the step it anneals from)")
    a.step_args = [] if a.sigma is None else ["--sigma", f"{a.sigma:g}"]
    if a.sigma_final is not None:
        a.step_args += ["--sigma-final", f"{a.sigma_final:g}", "--anneal-episodes", str(a.anneal_episodes)]
    a.mutation_tag = "" if a.sigma is None else (
        f"-m{a.sigma:g}" + ("" if a.sigma_final is None else f"-{a.sigma_final:g}-{a.anneal_episodes}"))
    a.method_seeds = a.method_seeds or a.seeds
    a.sweep_seeds = a.sweep_seeds or a.seeds
    a.periods = [float(x) for x in a.periods.split(",") if x]
    a.complexities = [int(x) for x in a.complexities.split(",") if x]
    a.figures = {int(x) for x in a.figures.split(",") if x}
    if min(a.seeds, a.method_seeds, a.sweep_seeds, a.episodes, a.sweep_episodes, a.jobs) < 1:
        p.error("--seeds, --method-seeds, --sweep-seeds, --episodes, --sweep-episodes and --jobs must be positive")
    return a


def run_id(method, period, complexity, episodes, seed, duration):
    tail = "" if duration == 60.0 else f"-d{duration:g}"
    return f"{method}-t{period:g}-n{complexity}-e{episodes}-s{seed}{tail}"


def plan(a):
    """The set of runs the selected figures need (deduplicated)."""
    def seeds(n):
        return range(a.first_seed, a.first_seed + n)

    runs = {}

    def add(method, period, complexity, episodes, seed):
        key = run_id(method, period, complexity, episodes, seed, a.duration) + a.mutation_tag
        runs[key] = dict(method=method, period=period, complexity=complexity, episodes=episodes, seed=seed)

    # The headline runs first (historical, t = 4 s, n = 5): they are what a cut-short
    # budget should still deliver; then the baselines, then the sweeps.
    if a.figures & {6, 7}:
        for s in seeds(a.seeds):
            add("historical", 4.0, 5, a.episodes, s)
    if 6 in a.figures:
        for s in seeds(a.method_seeds):
            for m in ("leniency", "average"):
                add(m, 4.0, 5, a.episodes, s)
    for s in seeds(a.sweep_seeds):
        if 8 in a.figures:
            for t in a.periods:
                add("historical", t, 5, a.sweep_episodes, s)
        if 9 in a.figures:
            for n in a.complexities:
                add("historical", 4.0, n, a.sweep_episodes, s)
    return runs


def run_one(a, key, r, progress):
    d = pathlib.Path(a.out) / "runs" / key
    d.mkdir(parents=True, exist_ok=True)
    summary = d / "summary.json"
    if summary.exists():
        progress(key, "done already")
        return
    ckpt = d / "checkpoint"
    cmd = ["evolve", "--robot", a.robot, "--method", r["method"], "--period", f"{r['period']:g}",
           "--complexity", str(r["complexity"]), "--episodes", str(r["episodes"]), "--seed", str(r["seed"]),
           "--duration", f"{a.duration:g}", "--threads", "1", "--checkpoint", str(ckpt), "--out", str(d / "policy.json"),
           "--log", str(d / "curve.csv"), "--json"] + a.step_args
    if (ckpt / "checkpoint.json").exists():
        cmd.append("--resume")
    progress(key, "started")
    t0 = time.monotonic()
    try:
        result = program.run(a.tensegrity, cmd)
    except program.RunError as e:  # an exception, not an exit: one failed run must not stop the others
        raise RuntimeError(f"{key}: {e}") from None
    result.update(r)
    tmp = summary.with_suffix(".tmp")
    tmp.write_text(json.dumps(result, indent=2) + "\n")
    tmp.replace(summary)
    progress(key, f"best {result['final_score_m']:.2f} m in {time.monotonic() - t0:.0f} s")


def run_all(a, runs):
    lock = threading.Lock()
    finished = [0]

    def progress(key, what):
        with lock:
            if what != "started":
                finished[0] += 1
            print(f"[{finished[0]}/{len(runs)}] {key}: {what}", flush=True)

    failures = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as pool:
        futures = {pool.submit(run_one, a, k, r, progress): k for k, r in runs.items()}
        for f in concurrent.futures.as_completed(futures):
            try:
                f.result()
            except Exception as e:  # one failed run must not lose the others
                failures.append(str(e))
                print(f"experiments: {e}", file=sys.stderr, flush=True)
    return failures


def load(a, planned):
    out = {}
    for key, r in planned.items():
        d = pathlib.Path(a.out) / "runs" / key
        if (d / "summary.json").exists():
            out[key] = dict(r, summary=json.loads((d / "summary.json").read_text()),
                            curve=runs.read_curve(d / "curve.csv"))
    return out


def finished_runs(a):
    """Every finished run in OUT/runs made with this step and episode length, whatever
    subset of the grid or seeds the command that made it asked for: a sweep run in
    parts (a few points first, more seeds later) draws all of them every time."""
    found = {}
    for summary in sorted((pathlib.Path(a.out) / "runs").glob("*/summary.json")):
        try:
            s = json.loads(summary.read_text())
            r = dict(method=s["method"], period=float(s["period"]), complexity=int(s["complexity"]),
                     episodes=int(s["episodes"]), seed=int(s["seed"]))
        except (ValueError, KeyError, TypeError) as e:
            print(f"experiments: {summary}: skipped, not a run summary ({e})", file=sys.stderr)
            continue
        key = run_id(r["method"], r["period"], r["complexity"], r["episodes"], r["seed"], a.duration)
        if key + a.mutation_tag == summary.parent.name:
            found[summary.parent.name] = r
    return found


def pyplot():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        return plt
    except ImportError:
        print("experiments: matplotlib missing (Debian: python3-matplotlib; run with /usr/bin/python3): CSV only",
              file=sys.stderr)
        return None


def report(a, planned):
    """The figures and summary.json from what is asked for now and what finished before."""
    drawn = {**finished_runs(a), **planned}
    done = load(a, drawn)
    out, plt = pathlib.Path(a.out), pyplot()
    summary = {"episodes": a.episodes, "sweep_episodes": a.sweep_episodes, "seeds": a.seeds,
               "method_seeds": a.method_seeds, "sweep_seeds": a.sweep_seeds, "robot": a.robot}
    if 6 in a.figures:
        summary["methods"] = experiment_figures.figure6(done, a.episodes, out, plt)
    if 7 in a.figures:
        summary["learning"] = experiment_figures.figure7(done, a.episodes, out, plt)
    if 8 in a.figures:
        summary["period"] = experiment_figures.figure8(done, a.sweep_episodes, a.periods, out, plt)
    if 9 in a.figures:
        summary["complexity"] = experiment_figures.figure9(done, a.sweep_episodes, a.complexities, out, plt)
    summary["runs_done"], summary["runs_planned"] = len(done), len(drawn)
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    print(json.dumps(summary, indent=2))


def main():
    a = parse_args()
    pathlib.Path(a.out).mkdir(parents=True, exist_ok=True)
    runs = plan(a)
    failures = []
    if not a.plot_only:
        pin_robot(a)
        a.tensegrity = program.find(a.tensegrity)
        pin_settings(a)
        print(f"experiments: {len(runs)} runs, {a.jobs} at a time, into {a.out}", flush=True)
        failures = run_all(a, runs)
    report(a, runs)
    if failures:
        sys.exit(f"experiments: {len(failures)} run(s) failed")


if __name__ == "__main__":
    main()
