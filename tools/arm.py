#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Run one arm of a controlled comparison: N seeds of `tensegrity evolve` with the
same settings, and summarise them.

An arm is a robot file (optionally changed by --set), evolve options and a seed
range. Each seed runs in OUT/runs/sK/ with a checkpoint after every generation,
so the script can be stopped and started again: finished seeds are reused,
unfinished ones resume. Seeds run --jobs at a time under `nice`.

Summary (OUT/arm.json, OUT/arm.csv, OUT/arm.png), at every --at budget:
best team so far per seed, median and quartiles over seeds, seeds >= 28 m and
>= 32 m, the episode of each seed's first team >= 28 m and >= 32 m (earliest
over seeds, and the median over all seeds, counting a seed that never got there
as later than the budget), the generation mean
(last 5 generations before the budget), the infeasible share of the first 10
generations.

Examples:
  tools/arm.py --out out/arms/gauss-d005 --robot robots/superball-ntrt2014.json \\
      --set time_step_s=0.002 --seeds 10 --episodes 1000 -- --mutation gaussian
  tools/arm.py --compare out/arms/A out/arms/B --out out/arms/compare --at 1000

With --compare the first arm is the control: every other arm is tested against it
at each budget both reached (tools/tensegrity_tools/arm_stats.py: Mann-Whitney on the bests, Fisher
on the seeds >= 28 m, log-rank on the episode of the first team >= 32 m). An arm is
its directory, or the arm.csv it wrote (as kept in docs/results/arms/), so a
recorded arm can be the control of one run on another machine:
  tools/arm.py --compare docs/results/arms/ode-replica-5000.csv out/arms/pop40 --out C

An arm too long for one sitting is kept with --pack DIR (tools/tensegrity_tools/arm_keep.py) and carried
on elsewhere: copy DIR to a new --out and run the same command; each seed resumes from
its packed checkpoint, also with a larger --episodes.
"""
import argparse
import concurrent.futures
import csv
import json
import pathlib
import statistics
import sys

from tensegrity_tools import arm_keep, arm_stats, program, robot_file, runs

ROOT = program.ROOT
TARGET_M = 32.0
NEAR_M = 28.0
# An arm's arm.csv: one row per seed and budget.
RECORDED_COLUMNS = ["budget", "seed", "episodes", "best_m", "generation_mean_m", "first_episode_28m",
                    "first_episode_32m", "infeasible_first10"]


def parse_args():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True, help="arm directory (or the comparison's, with --compare)")
    program.add_option(p)
    p.add_argument("--robot", default=str(ROOT / "robots/superball-paper.json"),
                   help="robot description (default: the default robot, the paper's simulated SUPERball)")
    robot_file.add_set_option(p)
    p.add_argument("--seeds", type=int, default=10, help="seeds per arm (default: %(default)s)")
    p.add_argument("--first-seed", type=int, default=1)
    p.add_argument("--episodes", type=int, default=1000, help="episode budget per seed (default: %(default)s)")
    p.add_argument("--jobs", type=int, default=2, help="seeds at a time (default: %(default)s)")
    p.add_argument("--threads", type=int, default=1, help="evolve --threads per seed (default: %(default)s)")
    p.add_argument("--nice", type=int, default=10, help="niceness of the runs (default: %(default)s)")
    p.add_argument("--at", type=int, action="append", default=None,
                   help="budgets to summarise at (default: 1000, 2500, 5000 up to --episodes)")
    p.add_argument("--summary-only", action="store_true", help="summarise the runs there, run nothing")
    p.add_argument("--pack", metavar="DIR",
                   help="then copy the arm's runs to DIR to keep in the repository: curves, policies, summaries "
                        "and checkpoints (xz); an arm started from such a copy resumes each seed where it stopped")
    p.add_argument("--compare", nargs="+", metavar="ARM",
                   help="compare finished arms (directories, or their recorded arm.csv) instead of running "
                        "one; the first is the control")
    p.add_argument("evolve_args", nargs="*", help="more `tensegrity evolve` options (after --)")
    return p.parse_args()


def run_seed(args, robot, seed):
    run = pathlib.Path(args.out) / "runs" / f"s{seed}"
    run.mkdir(parents=True, exist_ok=True)
    try:
        arm_keep.unpack_checkpoint(run)
    except ValueError as e:
        return seed, f"FAILED: {e}"
    summary = run / "summary.json"
    if summary.exists() and json.loads(summary.read_text()).get("episodes", 0) >= args.episodes:
        return seed, "reused"
    evolve = ["evolve", "--robot", str(robot), "--episodes", str(args.episodes), "--seed", str(seed),
              "--threads", str(args.threads), "--checkpoint", str(run / "ckpt"), "--resume",
              "--out", str(run / "policy.json"), "--log", str(run / "curve.csv"), "--json"] + args.evolve_args
    try:
        result = program.run(args.tensegrity, evolve, nice=args.nice, stderr_path=run / "stderr.log")
    except program.RunError as e:
        return seed, f"FAILED: {e}"
    summary.write_text(json.dumps(result, indent=2) + "\n")
    (run / "command.txt").write_text(" ".join([args.tensegrity] + evolve) + "\n")
    return seed, "done"


def seed_metrics(curve, budget):
    rows = [r for r in curve if r["episodes"] <= budget]
    if not rows:
        return None
    first32 = next((int(r["episodes"]) for r in curve if r["best_so_far_m"] >= TARGET_M), None)
    first28 = next((int(r["episodes"]) for r in curve if r["best_so_far_m"] >= NEAR_M), None)
    early = curve[:10]
    return {
        "best_m": rows[-1]["best_so_far_m"],
        "generation_mean_m": statistics.fmean(r["mean_score_m"] for r in rows[-5:]),
        "first_episode_32m": first32 if first32 is not None and first32 <= budget else None,
        "first_episode_28m": first28 if first28 is not None and first28 <= budget else None,
        "infeasible_first10": sum(r["infeasible"] for r in early) / max(1.0, sum(r["teams"] for r in early)),
        "episodes": int(rows[-1]["episodes"]),
    }


def quartiles(values):
    if len(values) < 2:
        return (values[0], values[0], values[0]) if values else (None, None, None)
    q = statistics.quantiles(values, n=4, method="inclusive")
    return q[0], statistics.median(values), q[2]


def censored_median(episodes):
    """Median episode of a first success over all seeds; a seed without one (None) counts
    as later than the budget. None when the median itself is such a seed."""
    if not episodes:
        return None
    med = statistics.median([float("inf") if e is None else e for e in episodes])
    return None if med == float("inf") else med


def summarise_budget(per_seed, budget):
    best = [m["best_m"] for m in per_seed.values()]
    q1, med, q3 = quartiles(best)
    firsts = [m["first_episode_32m"] for m in per_seed.values() if m["first_episode_32m"] is not None]
    return {"budget": budget, "seeds": len(best), "median_m": med, "q1_m": q1, "q3_m": q3,
            "mean_m": statistics.fmean(best) if best else None, "min_m": min(best, default=None),
            "max_m": max(best, default=None), "seeds_ge_28": sum(b >= NEAR_M for b in best),
            "seeds_ge_32": sum(b >= TARGET_M for b in best),
            "first_episode_32m": min(firsts, default=None),
            "first_episode_28m": min((m["first_episode_28m"] for m in per_seed.values()
                                      if m["first_episode_28m"] is not None), default=None),
            "first_episode_28m_median": censored_median([m["first_episode_28m"] for m in per_seed.values()]),
            "first_episode_32m_median": censored_median([m["first_episode_32m"] for m in per_seed.values()]),
            "generation_mean_median_m": statistics.median([m["generation_mean_m"] for m in per_seed.values()])
            if best else None,
            "infeasible_first10_mean": statistics.fmean([m["infeasible_first10"] for m in per_seed.values()])
            if best else None}


def budgets(args, episodes):
    if args.at:
        return sorted(set(args.at))
    return [b for b in (500, 1000, 2500, 5000) if b <= episodes] or [episodes]


def summarise_arm(out, args, write=True):
    curve_files = sorted((out / "runs").glob("s*/curve.csv"), key=lambda p: int(p.parent.name[1:]))
    curves = {int(p.parent.name[1:]): runs.read_curve(p) for p in curve_files}
    curves = {s: c for s, c in curves.items() if c}
    episodes = max((int(c[-1]["episodes"]) for c in curves.values()), default=0)
    result = {"arm": out.name, "command": (out / "command.txt").read_text().strip()
              if (out / "command.txt").exists() else "", "at": []}
    rows = []
    for b in budgets(args, episodes):
        per_seed = {s: m for s, c in curves.items() if (m := seed_metrics(c, b)) and m["episodes"] >= b}
        if not per_seed:
            continue
        result["at"].append(summarise_budget(per_seed, b) | {"per_seed": per_seed})
        for s, m in per_seed.items():
            rows.append({"budget": b, "seed": s} | m)
    if not write:  # a comparison reads the arms and writes only its own files
        return result
    (out / "arm.json").write_text(json.dumps(result, indent=2) + "\n")
    with open(out / "arm.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=RECORDED_COLUMNS)
        w.writeheader()
        w.writerows(rows)
    if have_matplotlib():
        plot_arm(out, curves)
    return result


def add_recorded_row(per_budget, row, episode):
    per_budget.setdefault(int(row["budget"]), {})[int(row["seed"])] = {
        "best_m": float(row["best_m"]), "generation_mean_m": float(row["generation_mean_m"]),
        "first_episode_32m": episode(row["first_episode_32m"]), "first_episode_28m": episode(row["first_episode_28m"]),
        "infeasible_first10": float(row["infeasible_first10"]), "episodes": int(row["episodes"])}


def read_recorded_arm(path, args):
    """An arm as its arm.csv recorded it: the per-seed metrics at the budgets it kept
    (those of --at only, when given). No curves, so no plot of its own."""
    def episode(text):  # blank: no such team by that budget
        return int(float(text)) if text else None
    per_budget = {}
    with open(path) as f:
        reader = csv.DictReader(f)
        missing = [c for c in RECORDED_COLUMNS if c not in (reader.fieldnames or [])]
        if missing:
            sys.exit(f"arm.py: --compare: {path} is not an arm.csv: no column {', '.join(missing)}")
        for n, row in enumerate(reader, start=2):
            try:
                add_recorded_row(per_budget, row, episode)
            except ValueError as e:
                sys.exit(f"arm.py: --compare: {path}, line {n}: {e}")
    wanted = set(args.at) if args.at else set(per_budget)
    return {"arm": path.stem, "command": f"recorded in {path}",
            "at": [summarise_budget(per_seed, b) | {"per_seed": per_seed}
                   for b, per_seed in sorted(per_budget.items()) if b in wanted]}


def read_arm(path, args):
    path = pathlib.Path(path)
    return read_recorded_arm(path, args) if path.is_file() else summarise_arm(path, args, write=False)


def have_matplotlib():
    # The numbers are the result; a machine without matplotlib still gets them.
    try:
        import matplotlib  # noqa: F401
        return True
    except ImportError:
        print("arm.py: matplotlib not found, PNG plots skipped (the CSV and JSON are written)", file=sys.stderr)
        return False


def plot_arm(out, curves):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for s, c in sorted(curves.items()):
        ax.plot([r["episodes"] for r in c], [r["best_so_far_m"] for r in c], lw=0.8, alpha=0.6)
    if curves:
        n = min(len(c) for c in curves.values())
        x = [curves[next(iter(curves))][i]["episodes"] for i in range(n)]
        qs = [quartiles([c[i]["best_so_far_m"] for c in curves.values()]) for i in range(n)]
        ax.fill_between(x, [q[0] for q in qs], [q[2] for q in qs], color="k", alpha=0.15, label="quartiles")
        ax.plot(x, [q[1] for q in qs], "k", lw=2, label=f"median of {len(curves)} seeds")
    ax.axhline(TARGET_M, color="r", ls="--", lw=1, label="paper: 32 m")
    ax.set_xlabel("episodes")
    ax.set_ylabel("best team so far, m in 60 s")
    ax.set_title(out.name)
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "arm.png", dpi=110)
    plt.close(fig)


def compare(args):
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    # The first arm is the control: a mistyped one must not silently hand that role on.
    missing = [d for d in args.compare
               if not (pathlib.Path(d) / "runs").is_dir() and not pathlib.Path(d).is_file()]
    if missing:
        sys.exit(f"arm.py: --compare: neither an arm directory with runs/ nor an arm.csv: {', '.join(missing)}")
    arms = [read_arm(d, args) | {"dir": d} for d in args.compare]
    rows = []
    control = {at["budget"]: at for at in arms[0]["at"]} if arms else {}
    if len(arms) > 1 and not arm_stats.have_scipy():
        print("arm.py: scipy not found, p-values against the control skipped", file=sys.stderr)
    for i, arm in enumerate(arms):
        for at in arm["at"]:
            row = {k: v for k, v in at.items() if k != "per_seed"} | {"arm": arm["arm"]}
            if i > 0 and at["budget"] in control and arm_stats.have_scipy():
                row |= arm_stats.against_control(at, control[at["budget"]], NEAR_M)
            rows.append(row)
    (out / "compare.json").write_text(json.dumps(rows, indent=2) + "\n")
    fields = ["arm", "budget", "seeds", "median_m", "q1_m", "q3_m", "mean_m", "min_m", "max_m", "seeds_ge_28",
              "seeds_ge_32", "first_episode_28m", "first_episode_28m_median", "first_episode_32m",
              "first_episode_32m_median", "generation_mean_median_m", "infeasible_first10_mean",
              "p_mann_whitney", "p_fisher_28", "p_logrank_32"]
    with open(out / "compare.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    for r in rows:
        print(f"{r['arm']:<28} {r['budget']:>5} ep  n={r['seeds']:<2} median {r['median_m']:6.2f} "
              f"[{r['q1_m']:6.2f}, {r['q3_m']:6.2f}]  >=28: {r['seeds_ge_28']}  >=32: {r['seeds_ge_32']}  "
              f"first28: {r['first_episode_28m']} (median {r['first_episode_28m_median'] or '>' + str(r['budget'])})  "
              f"first32: {r['first_episode_32m']}  gen mean {r['generation_mean_median_m']:.2f}"
              + (f"  vs {arms[0]['arm']}: p {r['p_mann_whitney']:.3f} (Mann-Whitney), {r['p_fisher_28']:.3f} "
                 f"(Fisher >=28 m), {r['p_logrank_32']:.3f} (log-rank, first >=32 m)" if "p_mann_whitney" in r else ""))
    if have_matplotlib():
        plot_compare(out, arms)


def plot_compare(out, arms):
    """Left: every seed's best at each arm's last budget. Right: each arm's median and
    quartiles at every budget, with the seeds at 32 m or more written on the median."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(max(11, 1.3 * len(arms) + 6), 4.5),
                                  gridspec_kw={"width_ratios": [max(1, len(arms)), 3]})
    data, labels = [], []
    for arm in arms:
        if arm["at"]:
            last = arm["at"][-1]
            data.append([m["best_m"] for m in last["per_seed"].values()])
            labels.append(f"{arm['arm']}\n{last['budget']} ep, n={last['seeds']}")
    if data:
        ax.boxplot(data, labels=labels, showmeans=True)
        for i, d in enumerate(data, start=1):
            ax.scatter([i] * len(d), d, s=10, alpha=0.5)
    ax.axhline(TARGET_M, color="r", ls="--", lw=1)
    ax.set_ylabel("best team, m in 60 s")
    ax.tick_params(axis="x", labelsize=7)
    for i, arm in enumerate(arms):
        at = arm["at"]
        if not at:
            continue
        x = [a["budget"] for a in at]
        ax2.fill_between(x, [a["q1_m"] for a in at], [a["q3_m"] for a in at], color=f"C{i}", alpha=0.15)
        ax2.plot(x, [a["median_m"] for a in at], "o-", color=f"C{i}", ms=3, label=arm["arm"])
        for a in at:
            ax2.annotate(str(a["seeds_ge_32"]), (a["budget"], a["median_m"]), textcoords="offset points",
                         xytext=(0, 5), ha="center", fontsize=7, color=f"C{i}")
    ax2.axhline(TARGET_M, color="r", ls="--", lw=1)
    ax2.set_xlabel("episodes")
    ax2.set_ylabel("best so far: median and quartiles, m")
    ax2.set_title("numbers: seeds at 32 m or more", fontsize=8)
    ax2.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(out / "compare.png", dpi=110)
    plt.close(fig)


def main():
    args = parse_args()
    if args.compare and args.pack:
        sys.exit("--pack keeps one arm's runs; it does not go with --compare")
    if args.compare:
        compare(args)
        return
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    # A summary only reads: writing --robot's default into the arm would replace the
    # record of the robot its seeds learned on (it once did).
    if not args.summary_only:
        args.tensegrity = program.find(args.tensegrity)
        robot = robot_file.write_robot(args.robot, args.set, out)
        seeds = range(args.first_seed, args.first_seed + args.seeds)
        (out / "command.txt").write_text(" ".join([sys.argv[0]] + sys.argv[1:]) + "\n")
        with concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs) as pool:
            for seed, status in pool.map(lambda s: run_seed(args, robot, s), seeds):
                print(f"{out.name} seed {seed}: {status}", flush=True)
    result = summarise_arm(out, args)
    for at in result["at"]:
        print(f"{out.name} at {at['budget']}: median {at['median_m']:.2f} m [{at['q1_m']:.2f}, {at['q3_m']:.2f}], "
              f">=28 m {at['seeds_ge_28']}/{at['seeds']}, >=32 m {at['seeds_ge_32']}/{at['seeds']}, "
              f"first 32 m at {at['first_episode_32m']}")
    if args.pack:
        print(f"{out.name}: packed {len(arm_keep.pack(out, args.pack))} seeds into {args.pack}")


if __name__ == "__main__":
    main()
