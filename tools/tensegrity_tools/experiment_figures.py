# SPDX-License-Identifier: Apache-2.0
"""The paper's learning figures 6-9 from finished evolutions (tools/experiments.py):
one function per figure, each writing its CSV, its PNG (when matplotlib is there) and
its part of summary.json.

`done` maps a run's id to its parameters (method, period, complexity, episodes, seed)
with its `summary` (evolve --json) and `curve` (evolve --log, runs.read_curve).
"""
import csv
import statistics

from . import sweep_figure

# What the paper reports (Iscen et al., sections 5-6), for the plots and the page.
PAPER_PERIOD_M = {4: 33.0, 5: 27.0, 6: 22.5, 7: 19.0, 8: 18.0}
PAPER_BEST_T4_N5_M = 32.0
METHODS = ("historical", "leniency", "average")


def mean_sd(values):
    if not values:
        return float("nan"), float("nan")
    return statistics.fmean(values), (statistics.stdev(values) if len(values) > 1 else 0.0)


def of(done, method, period, complexity, episodes):
    """The finished runs of one configuration."""
    return [d for d in done.values()
            if (d["method"], d["period"], d["complexity"], d["episodes"]) == (method, period, complexity, episodes)]


def curves_by_generation(done, method, period, complexity, episodes, column):
    """Per generation: episodes, mean and sd over the seeds that reached it."""
    series = [d["curve"] for d in of(done, method, period, complexity, episodes)]
    rows = []
    for g in range(max((len(c) for c in series), default=0)):
        vals = [c[g][column] for c in series if g < len(c)]
        eps = next(c[g]["episodes"] for c in series if g < len(c))
        m, sd = mean_sd(vals)
        rows.append((g + 1, eps, m, sd, len(vals)))
    return rows


def finals(done, method, period, complexity, episodes):
    return [d["summary"]["final_score_m"] for d in of(done, method, period, complexity, episodes)]


def seed_finals(done, method, period, complexity, episodes):
    return {d["seed"]: d["summary"]["final_score_m"] for d in of(done, method, period, complexity, episodes)}


def write_csv(path, header, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def figure6(done, episodes, out, plt):
    """Fitness methods at t = 4 s, n = 5: best so far and generation mean. Its summary."""
    rows, fig_data, summary = [], {}, {}
    for m in METHODS:
        best = curves_by_generation(done, m, 4.0, 5, episodes, "best_so_far_m")
        mean = curves_by_generation(done, m, 4.0, 5, episodes, "mean_score_m")
        fig_data[m] = (best, mean)
        for b, mm in zip(best, mean):
            rows.append((m, b[0], int(b[1]), f"{b[2]:.4f}", f"{b[3]:.4f}", f"{mm[2]:.4f}", f"{mm[3]:.4f}", b[4]))
        f_mean, f_sd = mean_sd(finals(done, m, 4.0, 5, episodes))
        summary[m] = {"best_m": f_mean, "best_sd_m": f_sd,
                      "last_generation_mean_m": mean[-1][2] if mean else float("nan"),
                      "runs": len(finals(done, m, 4.0, 5, episodes))}
    write_csv(out / "fig6_methods.csv", ["method", "generation", "episodes", "best_so_far_m", "best_so_far_sd_m",
                                         "mean_score_m", "mean_score_sd_m", "seeds"], rows)
    if plt:
        plot_figure6(plt, out / "fig6_methods.png", fig_data, {m: summary[m]["runs"] for m in METHODS})
    return summary


def plot_figure6(plt, path, fig_data, seeds):
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
    ax.set_title(f"Figure 6: fitness methods (t = 4 s, n = 5; seeds: historical {seeds['historical']}, "
                 f"leniency {seeds['leniency']}, average {seeds['average']}; band = 1 sd)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def figure7(done, episodes, out, plt):
    """Learning of historical at t = 4 s, n = 5: best so far and the infeasible rate. Its summary."""
    best = curves_by_generation(done, "historical", 4.0, 5, episodes, "best_so_far_m")
    inf = curves_by_generation(done, "historical", 4.0, 5, episodes, "infeasible_rate")
    write_csv(out / "fig7_learning.csv", ["generation", "episodes", "best_so_far_m", "best_so_far_sd_m",
                                          "infeasible_rate", "infeasible_rate_sd", "seeds"],
              [(b[0], int(b[1]), f"{b[2]:.4f}", f"{b[3]:.4f}", f"{i[2]:.4f}", f"{i[3]:.4f}", b[4])
               for b, i in zip(best, inf)])
    f_mean, f_sd = mean_sd(finals(done, "historical", 4.0, 5, episodes))
    reach = [next((int(r["episodes"]) for r in d["curve"] if r["best_so_far_m"] >= PAPER_BEST_T4_N5_M), None)
             for d in of(done, "historical", 4.0, 5, episodes)]
    if plt and best:
        plot_figure7(plt, out / "fig7_learning.png", best, inf, len(reach))
    return {"best_m": f_mean, "best_sd_m": f_sd, "paper_m": PAPER_BEST_T4_N5_M, "episodes_to_32m": reach,
            "infeasible_rate_last": inf[-1][2] if inf else None}


def plot_figure7(plt, path, best, inf, seeds):
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
    ax.set_title(f"Figure 7: learning, historical average, t = 4 s, n = 5 ({seeds} seeds)")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def swept(done, field, asked, episodes, fixed):
    """The points of a sweep: those asked for and those finished runs hold."""
    found = {d[field] for d in done.values() if d["method"] == "historical" and d["episodes"] == episodes
             and fixed(d)}
    return sorted(set(asked) | found)


def sweep(done, episodes, out, plt, name, fig_no, keys, label, paper):
    """One sweep figure (8: period, 9: complexity); keys: (x, (period, complexity)). Its summary."""
    points = [(x, sweep_figure.point(seed_finals(done, "historical", period, n, episodes))) for x, (period, n) in keys]
    sweep_figure.write_csv(out / f"fig{fig_no}_{name}.csv", label, points, paper)
    if plt:
        sweep_figure.plot(plt, out / f"fig{fig_no}_{name}.png", f"Figure {fig_no}: {name}", label, points, paper,
                          episodes)
    return {f"{x:g}": {k: v for k, v in p.items() if k != "per_seed"} for x, p in points}


def figure8(done, episodes, periods, out, plt):
    periods = swept(done, "period", periods, episodes, lambda d: d["complexity"] == 5)
    return sweep(done, episodes, out, plt, "period", 8, [(t, (t, 5)) for t in periods], "period_s", PAPER_PERIOD_M)


def figure9(done, episodes, complexities, out, plt):
    complexities = swept(done, "complexity", complexities, episodes, lambda d: d["period"] == 4.0)
    return sweep(done, episodes, out, plt, "complexity", 9, [(n, (4.0, n)) for n in complexities], "complexity", {})
