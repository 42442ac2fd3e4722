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
import csv
import json
import os
import pathlib
import statistics
import subprocess
import sys
import threading
import time

import sweep_figure
from experiment_pins import pin_robot, pin_settings

ROOT = pathlib.Path(__file__).resolve().parent.parent

# What the paper reports (Iscen et al., sections 5-6), for the plots and the page.
PAPER_PERIOD_M = {4: 33.0, 5: 27.0, 6: 22.5, 7: 19.0, 8: 18.0}
PAPER_BEST_T4_N5_M = 32.0


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default="out/experiments", help="output directory (default: %(default)s)")
    p.add_argument("--tensegrity", default=str(ROOT / "build/release/cli/tensegrity"),
                   help="the tensegrity program (default: %(default)s)")
    p.add_argument("--robot", default=str(ROOT / "robots/superball-paper.json"),
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
    cmd = [a.tensegrity, "evolve", "--robot", a.robot, "--method", r["method"], "--period", f"{r['period']:g}",
           "--complexity", str(r["complexity"]), "--episodes", str(r["episodes"]), "--seed", str(r["seed"]),
           "--duration", f"{a.duration:g}", "--threads", "1", "--checkpoint", str(ckpt), "--out", str(d / "policy.json"),
           "--log", str(d / "curve.csv"), "--json"] + a.step_args
    if (ckpt / "checkpoint.json").exists():
        cmd.append("--resume")
    progress(key, "started")
    t0 = time.monotonic()
    done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{key}: tensegrity evolve failed ({done.returncode}): {done.stderr.strip()}")
    result = json.loads(done.stdout)
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


def read_curve(path):
    with open(path) as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def load(a, runs):
    out = {}
    for key, r in runs.items():
        d = pathlib.Path(a.out) / "runs" / key
        if (d / "summary.json").exists():
            out[key] = dict(r, summary=json.loads((d / "summary.json").read_text()), curve=read_curve(d / "curve.csv"))
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


def mean_sd(values):
    if not values:
        return float("nan"), float("nan")
    return statistics.fmean(values), (statistics.stdev(values) if len(values) > 1 else 0.0)


def curves_by_generation(done, method, period, complexity, episodes, column):
    """Per generation: episodes, mean and sd over the seeds that reached it."""
    series = [d["curve"] for d in done.values()
              if (d["method"], d["period"], d["complexity"], d["episodes"]) == (method, period, complexity, episodes)]
    rows = []
    for g in range(max((len(c) for c in series), default=0)):
        vals = [c[g][column] for c in series if g < len(c)]
        eps = next(c[g]["episodes"] for c in series if g < len(c))
        m, sd = mean_sd(vals)
        rows.append((g + 1, eps, m, sd, len(vals)))
    return rows


def finals(done, method, period, complexity, episodes):
    return [d["summary"]["final_score_m"] for d in done.values()
            if (d["method"], d["period"], d["complexity"], d["episodes"]) == (method, period, complexity, episodes)]


def seed_finals(done, method, period, complexity, episodes):
    return {d["seed"]: d["summary"]["final_score_m"] for d in done.values()
            if (d["method"], d["period"], d["complexity"], d["episodes"]) == (method, period, complexity, episodes)}


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def report(a, runs):
    drawn = {**finished_runs(a), **runs}  # what the page shows: asked for now, or finished before
    done = load(a, drawn)
    out = pathlib.Path(a.out)
    summary = {"episodes": a.episodes, "sweep_episodes": a.sweep_episodes, "seeds": a.seeds,
               "method_seeds": a.method_seeds, "sweep_seeds": a.sweep_seeds, "robot": a.robot}
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        plt = None
        print("experiments: matplotlib missing (Debian: python3-matplotlib; run with /usr/bin/python3): CSV only",
              file=sys.stderr)

    if 6 in a.figures:
        rows, fig_data, summary["methods"] = [], {}, {}
        for m in ("historical", "leniency", "average"):
            best = curves_by_generation(done, m, 4.0, 5, a.episodes, "best_so_far_m")
            mean = curves_by_generation(done, m, 4.0, 5, a.episodes, "mean_score_m")
            fig_data[m] = (best, mean)
            for b, mm in zip(best, mean):
                rows.append((m, b[0], int(b[1]), f"{b[2]:.4f}", f"{b[3]:.4f}", f"{mm[2]:.4f}", f"{mm[3]:.4f}", b[4]))
            f_mean, f_sd = mean_sd(finals(done, m, 4.0, 5, a.episodes))
            last_mean = mean[-1][2] if mean else float("nan")
            summary["methods"][m] = {"best_m": f_mean, "best_sd_m": f_sd, "last_generation_mean_m": last_mean,
                                     "runs": len(finals(done, m, 4.0, 5, a.episodes))}
        write_csv(out / "fig6_methods.csv", ["method", "generation", "episodes", "best_so_far_m", "best_so_far_sd_m",
                                             "mean_score_m", "mean_score_sd_m", "seeds"], rows)
        if plt:
            fig, ax = plt.subplots(figsize=(8, 5))
            for m, colour in zip(fig_data, ("C0", "C1", "C2")):
                best, mean = fig_data[m]
                if not best:
                    continue
                x = [r[1] for r in best]
                ax.plot(x, [r[2] for r in best], color=colour, label=f"{m}: best so far")
                ax.fill_between(x, [r[2] - r[3] for r in best], [r[2] + r[3] for r in best], color=colour, alpha=0.15)
                ax.plot(x, [r[2] for r in mean], color=colour, linestyle="--", label=f"{m}: mean of generation")
            ax.set_xlabel("episodes")
            ax.set_ylabel("distance in 60 s, m")
            seeds = {m: summary["methods"][m]["runs"] for m in fig_data}
            ax.set_title(f"Figure 6: fitness methods (t = 4 s, n = 5; seeds: historical {seeds['historical']}, "
                         f"leniency {seeds['leniency']}, average {seeds['average']}; band = 1 sd)")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
            fig.tight_layout()
            fig.savefig(out / "fig6_methods.png", dpi=110)
            plt.close(fig)

    if 7 in a.figures:
        best = curves_by_generation(done, "historical", 4.0, 5, a.episodes, "best_so_far_m")
        inf = curves_by_generation(done, "historical", 4.0, 5, a.episodes, "infeasible_rate")
        write_csv(out / "fig7_learning.csv", ["generation", "episodes", "best_so_far_m", "best_so_far_sd_m",
                                              "infeasible_rate", "infeasible_rate_sd", "seeds"],
                  [(b[0], int(b[1]), f"{b[2]:.4f}", f"{b[3]:.4f}", f"{i[2]:.4f}", f"{i[3]:.4f}", b[4])
                   for b, i in zip(best, inf)])
        f_mean, f_sd = mean_sd(finals(done, "historical", 4.0, 5, a.episodes))
        reach = [next((int(r["episodes"]) for r in d["curve"] if r["best_so_far_m"] >= PAPER_BEST_T4_N5_M), None)
                 for d in done.values()
                 if (d["method"], d["period"], d["complexity"], d["episodes"]) == ("historical", 4.0, 5, a.episodes)]
        summary["learning"] = {"best_m": f_mean, "best_sd_m": f_sd, "paper_m": PAPER_BEST_T4_N5_M,
                               "episodes_to_32m": reach,
                               "infeasible_rate_last": inf[-1][2] if inf else None}
        if plt and best:
            fig, ax = plt.subplots(figsize=(8, 5))
            x = [r[1] for r in best]
            ax.errorbar(x, [r[2] for r in best], yerr=[r[3] for r in best], color="C0", errorevery=max(1, len(x) // 20),
                        capsize=2, label="best so far, m")
            ax.axhline(PAPER_BEST_T4_N5_M, color="grey", linestyle=":", label="paper: 32 m")
            ax.set_xlabel("episodes")
            ax.set_ylabel("distance in 60 s, m")
            ax2 = ax.twinx()
            ax2.plot(x, [100 * r[2] for r in inf], color="C3", alpha=0.7, label="infeasible, %")
            ax2.set_ylabel("infeasible teams, %")
            ax2.set_ylim(0, 100)
            h1, l1 = ax.get_legend_handles_labels()
            h2, l2 = ax2.get_legend_handles_labels()
            ax.legend(h1 + h2, l1 + l2, fontsize=8, loc="center right")
            ax.set_title(f"Figure 7: learning, historical average, t = 4 s, n = 5 ({len(reach)} seeds)")
            ax.grid(alpha=0.3)
            fig.tight_layout()
            fig.savefig(out / "fig7_learning.png", dpi=110)
            plt.close(fig)

    def sweep(name, fig_no, keys, label, paper):
        points = [(x, sweep_figure.point(seed_finals(done, "historical", period, n, a.sweep_episodes)))
                  for x, (period, n) in keys]
        sweep_figure.write_csv(out / f"fig{fig_no}_{name}.csv", label, points, paper)
        summary[name] = {f"{x:g}": {k: v for k, v in p.items() if k != "per_seed"} for x, p in points}
        if plt:
            sweep_figure.plot(plt, out / f"fig{fig_no}_{name}.png", f"Figure {fig_no}: {name}", label, points,
                              paper, a.sweep_episodes)

    def swept(field, asked, fixed):
        found = {d[field] for d in done.values() if d["method"] == "historical"
                 and d["episodes"] == a.sweep_episodes and fixed(d)}
        return sorted(set(asked) | found)

    if 8 in a.figures:
        periods = swept("period", a.periods, lambda d: d["complexity"] == 5)
        sweep("period", 8, [(t, (t, 5)) for t in periods], "period_s", PAPER_PERIOD_M)
    if 9 in a.figures:
        complexities = swept("complexity", a.complexities, lambda d: d["period"] == 4.0)
        sweep("complexity", 9, [(n, (4.0, n)) for n in complexities], "complexity", {})

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
        if not os.access(a.tensegrity, os.X_OK):
            sys.exit(f"experiments: {a.tensegrity} is not an executable (build: cmake --preset release && "
                     f"cmake --build --preset release --target tensegrity)")
        pin_settings(a)
        print(f"experiments: {len(runs)} runs, {a.jobs} at a time, into {a.out}", flush=True)
        failures = run_all(a, runs)
    report(a, runs)
    if failures:
        sys.exit(f"experiments: {len(failures)} run(s) failed")


if __name__ == "__main__":
    main()
