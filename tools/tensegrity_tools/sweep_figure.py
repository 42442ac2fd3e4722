# SPDX-License-Identifier: Apache-2.0
"""Figures 8 and 9 (tools/experiments.py): one point per period or complexity, each
the best team of several seeds' evolutions.

On this model a point's seeds split between a plateau (5-10 m) and rolling modes of
30-39 m (docs/reproduction.md), so a mean and standard deviation
alone would draw a bimodal point as one wide bar. The CSV and the plot give the mean
with its sd (the paper's kind of error bar), the median and quartiles, the seeds at
32 m or more, and every seed's own value.
"""
import csv
import statistics

TARGET_M = 32.0


def point(values):
    """Summary of one point's per-seed bests (a dict seed -> m)."""
    v = list(values.values())
    if not v:
        return {"seeds": 0}
    q = statistics.quantiles(v, n=4, method="inclusive") if len(v) > 1 else [v[0], v[0], v[0]]
    return {"seeds": len(v), "mean_m": statistics.fmean(v), "sd_m": statistics.stdev(v) if len(v) > 1 else 0.0,
            "median_m": statistics.median(v), "q1_m": q[0], "q3_m": q[2],
            "seeds_ge_32": sum(x >= TARGET_M for x in v), "per_seed": dict(sorted(values.items()))}


def write_csv(path, label, points, paper):
    """points: list of (x, summary); paper: x -> the paper's distance, where it gives one."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow([label, "best_m", "best_sd_m", "median_m", "q1_m", "q3_m", "seeds", "seeds_ge_32m",
                    "per_seed_m", "paper_m"])
        for x, p in points:
            if not p["seeds"]:
                w.writerow([f"{x:g}", "", "", "", "", "", 0, 0, "", paper.get(x, "")])
                continue
            w.writerow([f"{x:g}", f"{p['mean_m']:.4f}", f"{p['sd_m']:.4f}", f"{p['median_m']:.4f}",
                        f"{p['q1_m']:.4f}", f"{p['q3_m']:.4f}", p["seeds"], p["seeds_ge_32"],
                        " ".join(f"s{s}:{m:.2f}" for s, m in p["per_seed"].items()), paper.get(x, "")])


def plot(plt, path, title, label, points, paper, episodes):
    shown = [(x, p) for x, p in points if p["seeds"]]
    if not shown:
        return
    fig, ax = plt.subplots(figsize=(7.5, 4.6))
    xs = [x for x, _ in shown]
    ax.errorbar(xs, [p["mean_m"] for _, p in shown], yerr=[p["sd_m"] for _, p in shown], fmt="o-", capsize=3,
                color="C0", label="this model: mean ± sd")
    ax.plot(xs, [p["median_m"] for _, p in shown], "D--", color="C1", ms=4, lw=1, label="median")
    for x, p in shown:
        ax.scatter([x] * p["seeds"], list(p["per_seed"].values()), s=12, color="k", alpha=0.45, zorder=3)
    ax.scatter([], [], s=12, color="k", alpha=0.45, label="each seed")
    if paper:
        ax.plot(list(paper), list(paper.values()), "s:", color="grey", label="paper")
    ax.axhline(TARGET_M, color="r", ls="--", lw=0.8)
    seeds = max(p["seeds"] for _, p in shown)
    ax.set_xlabel(label.replace("_", " "))
    ax.set_ylabel("best team, m in 60 s")
    ax.set_title(f"{title} (up to {seeds} seeds per point, {episodes} episodes)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
