#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Draws the PNGs of `tensegrity analyze` from the CSV files it wrote (Figures 10-12
of Iscen et al. and the rolling evidence). Plotting only: every number is computed by
the C++ analysis (sim/analysis/). Exit status 3: matplotlib is not installed.

usage: tools/plot_analysis.py DIR
"""
import csv
import json
import os
import sys

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("plot_analysis: matplotlib missing (Debian: python3-matplotlib); CSV only", file=sys.stderr)
    sys.exit(3)

DPI = 80  # small PNGs: docs/results/analysis/ commits them


def read(path):
    """Columns of a CSV file by name, as floats (empty cells: None)."""
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return {h: [float(r[i]) if r[i] != "" else None for r in body] for i, h in enumerate(header)}


def matrix(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))[1:]
    return [[float(v) for v in r[1:]] for r in rows]


def title(summary, what):
    return f"{what} ({os.path.basename(summary['policy'])}, {summary['robot']})"


def fig10(d, s):
    m = read(os.path.join(d, "fig10_11_muscles.csv"))
    fig, ax = plt.subplots(figsize=(9, 3.6))
    for c, lo, hi, mean in zip(m["cable"], m["rest_min_m"], m["rest_max_m"], m["rest_mean_m"]):
        ax.add_patch(plt.Rectangle((c - 0.35, lo), 0.7, hi - lo, fill=False, edgecolor="k", linestyle="--"))
        ax.plot([c - 0.35, c + 0.35], [mean, mean], color="tab:red", linewidth=2)
    ax.set_xlim(-1, len(m["cable"]))
    ax.set_ylim(min(m["rest_min_m"]) - 0.05, max(m["rest_max_m"]) + 0.05)
    ax.set_xticks(range(len(m["cable"])))
    ax.set_xlabel("cable (muscle), project index")
    ax.set_ylabel("rest length (m)")
    w = s["window_s"]
    ax.set_title(title(s, f"Fig. 10: rest-length interval and mean, {w[0]:.0f}-{w[1]:.0f} s"), fontsize=9)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig10_rest_lengths.png"), dpi=DPI)
    plt.close(fig)


def smooth(values, width):
    out = []
    for k in range(len(values)):
        lo, hi = max(0, k - width // 2), min(len(values), k + width // 2 + 1)
        out.append(sum(values[lo:hi]) / (hi - lo))
    return out


def fig11_time(d, s):
    t = read(os.path.join(d, "fig11_timeseries.csv"))
    time = t["time_s"]
    fig, axes = plt.subplots(5, 1, figsize=(9, 10), sharex=True)
    axes[0].plot(time, t["rest_mean_m"], label="mean rest length (signal)")
    axes[0].plot(time, t["length_mean_m"], label="mean actual length")
    axes[0].set_ylabel("length (m)")
    axes[1].plot(time, t["tension_mean_n"], label="mean tension")
    axes[1].plot(time, t["tension_max_n"], label="largest tension", linewidth=0.6)
    axes[1].set_ylabel("tension (N)")
    axes[2].plot(time, t["kinetic_j"], color="tab:purple", label="kinetic energy")
    axes[2].set_ylabel("energy (J)")
    axes[3].plot(time, t["elastic_j"], color="tab:brown", label="potential energy in the cables")
    axes[3].set_ylabel("energy (J)")
    rate = (len(time) - 1) / (time[-1] - time[0])
    axes[4].plot(time, t["power_mean_w"], color="tab:gray", linewidth=0.4, label="mean power per muscle")
    axes[4].plot(time, smooth(t["power_mean_w"], int(round(rate))), color="tab:green", label="1 s average")
    axes[4].set_ylabel("power (W)")
    axes[4].set_xlabel("time (s)")
    for ax, letter in zip(axes, "abcde"):
        ax.legend(loc="upper right", fontsize=7)
        ax.grid(alpha=0.3)
        ax.set_title(f"({letter})", loc="left", fontsize=9)
    p = s["revolution_period_s"]
    axes[0].set_title(title(s, f"Fig. 11: revolution {p['contacts']:.2f} s (contacts), "
                               f"{p['rotation']:.2f} s (rotation); signal period {s['period_s']:g} s"),
                      fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig11_time.png"), dpi=DPI)
    plt.close(fig)


def fig11_muscles(d, s):
    m = read(os.path.join(d, "fig10_11_muscles.csv"))
    c = m["cable"]
    fig, axes = plt.subplots(3, 1, figsize=(9, 7), sharex=True)
    axes[0].bar([x - 0.2 for x in c], m["rest_mean_m"], 0.4, label="mean rest length")
    axes[0].bar([x + 0.2 for x in c], m["length_mean_m"], 0.4, label="mean actual length")
    axes[0].set_ylim(min(m["rest_mean_m"]) - 0.1, max(m["length_mean_m"]) + 0.05)
    axes[0].set_ylabel("m")
    axes[1].bar(c, m["tension_max_n"], 0.6, color="tab:red", alpha=0.4, label="peak tension")
    axes[1].bar(c, m["tension_mean_n"], 0.6, color="tab:red", label="mean tension")
    axes[1].set_ylabel("N")
    axes[2].bar(c, m["power_mean_w"], 0.6, color="tab:green", label="mean motor power")
    axes[2].set_ylabel("W")
    axes[2].set_xlabel("cable (muscle)")
    axes[2].set_xticks(range(len(c)))
    for ax in axes:
        ax.legend(loc="upper right", fontsize=7)
        ax.grid(alpha=0.3)
    axes[0].set_title(title(s, "Fig. 11, per muscle"), fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig11_muscles.png"), dpi=DPI)
    plt.close(fig)


def leaf_order(linkage, n):
    """Leaves left to right (the C++ tree lists them in the same order)."""
    def leaves(i):
        return [i] if i < n else leaves(int(linkage["a"][i - n])) + leaves(int(linkage["b"][i - n]))
    return leaves(2 * n - 2)


def draw_dendrogram(ax, linkage, n, cut):
    order = leaf_order(linkage, n)
    x = {leaf: i for i, leaf in enumerate(order)}
    y = {leaf: 0.0 for leaf in order}
    for k in range(n - 1):
        a, b, h = int(linkage["a"][k]), int(linkage["b"][k]), linkage["height"][k]
        ax.plot([x[a], x[a], x[b], x[b]], [y[a], h, h, y[b]], color="tab:blue", linewidth=1)
        x[n + k], y[n + k] = (x[a] + x[b]) / 2, h
    ax.axhline(cut, color="tab:red", linestyle="--", linewidth=0.8, label=f"cut at {cut:g}")
    ax.set_xticks(range(n))
    ax.set_xticklabels(order, fontsize=7)
    ax.set_ylabel("1 - r (average linkage)")
    ax.legend(loc="upper right", fontsize=7)
    return order


def fig12(d, s):
    n = len(matrix(os.path.join(d, "fig12_correlation.csv")))
    cut = s["clusters"]["cut_height"]
    fig, axes = plt.subplots(2, 1, figsize=(9, 6))
    orders = []
    for ax, name, what in ((axes[0], "fig12_linkage.csv", "zero lag: muscles that move together"),
                           (axes[1], "fig12_aligned_linkage.csv", "each pair at its best lag: same shape, any phase")):
        orders.append(draw_dendrogram(ax, read(os.path.join(d, name)), n, cut))
        ax.set_title(what, fontsize=9)
    axes[0].set_title(title(s, "Fig. 12: clustering of the rest-length signals") + "\n" + axes[0].get_title(),
                      fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig12_dendrogram.png"), dpi=DPI)
    plt.close(fig)

    fig, axes = plt.subplots(1, 2, figsize=(10, 4.6))
    for ax, name, order, what in ((axes[0], "fig12_correlation.csv", orders[0], "r at zero lag"),
                                  (axes[1], "fig12_aligned_correlation.csv", orders[1], "best r over lags")):
        r = matrix(os.path.join(d, name))
        image = ax.imshow([[r[i][j] for j in order] for i in order], vmin=-1, vmax=1, cmap="RdBu_r")
        ax.set_xticks(range(n))
        ax.set_yticks(range(n))
        ax.set_xticklabels(order, fontsize=6)
        ax.set_yticklabels(order, fontsize=6)
        ax.set_title(f"{what}, in dendrogram order", fontsize=9)
    fig.colorbar(image, ax=list(axes), shrink=0.8)
    fig.savefig(os.path.join(d, "fig12_correlation.png"), dpi=DPI)
    plt.close(fig)
    fig12_signals(d, s, orders[1])


def fig12_signals(d, s, order):
    """The paper's Figure 12: each signal normalised into [i, i + 1] over its last period;
    right, shifted to line up with the first signal of the order, in the order."""
    sig = read(os.path.join(d, "fig12_signals.csv"))
    lag = matrix(os.path.join(d, "fig12_aligned_lag_samples.csv"))
    time = sig["time_s"]
    rate = (len(time) - 1) / (time[-1] - time[0])
    per = int(round(s["period_s"] * rate))
    n = len(lag)
    fig, axes = plt.subplots(1, 2, figsize=(10, 7), sharey=True)
    for row, (ax, cables) in enumerate(((axes[0], list(range(n))), (axes[1], order))):
        for i, c in enumerate(cables):
            v = sig[f"cable{c}_rest_m"][-per:]
            if row == 1:
                shift = int(lag[order[0]][c]) % per
                v = v[shift:] + v[:shift]
            lo, hi = min(v), max(v)
            norm = [(x - lo) / (hi - lo) if hi > lo else 0.5 for x in v]
            ax.plot([k / rate for k in range(per)], [i + 0.9 * y for y in norm], linewidth=1)
        ax.set_yticks([i + 0.45 for i in range(n)])
        ax.set_yticklabels(cables, fontsize=6)
        ax.set_xlabel("time in the last period (s)")
    axes[0].set_title("signals, cable order", fontsize=9)
    axes[1].set_title("shifted to their best lag, clustered order", fontsize=9)
    fig.suptitle(title(s, "Fig. 12: rest-length signals, normalised"), fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "fig12_signals.png"), dpi=DPI)
    plt.close(fig)


def rolling(d, s):
    c = read(os.path.join(d, "contacts.csv"))
    time = c["time_s"]
    n = s["endcaps"]
    fig, axes = plt.subplots(2, 1, figsize=(9, 5.5), sharex=True)
    for e in range(n):
        touching = c[f"endcap{e}_touching"]
        spans, start = [], None
        for k, v in enumerate(touching + [0.0]):
            if v and start is None:
                start = k
            if not v and start is not None:
                spans.append((time[start], time[min(k, len(time) - 1)] - time[start]))
                start = None
        axes[0].broken_barh(spans, (e - 0.4, 0.8), color="k")
        slip = [(t, v) for t, v in zip(time, c[f"endcap{e}_slip_m_per_s"]) if v is not None]
        if slip:
            axes[1].plot(*zip(*slip), ".", markersize=1.5)
    r = s["rolling"]
    axes[0].set_yticks(range(n))
    axes[0].set_ylabel("end cap on the ground")
    axes[0].set_title(title(s, f"{r['endcaps_touched_count']} of {n} end caps touched, "
                               f"{len(r['face_sequence'])} ground faces, {r['revolutions']:.2f} revolutions"),
                      fontsize=9)
    axes[1].set_ylabel("slip speed (m/s)")
    axes[1].set_xlabel("time (s)")
    axes[1].set_title(f"horizontal speed of end caps on the ground: median {r['slip_m_per_s']['median']:.3f}, "
                      f"95th percentile {r['slip_m_per_s']['p95']:.3f} m/s", fontsize=9)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "rolling.png"), dpi=DPI)
    plt.close(fig)


def main():
    if len(sys.argv) != 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0 if len(sys.argv) == 2 else 2
    d = sys.argv[1]
    # The summary as far as `tensegrity analyze` has it when it calls this script.
    s = json.load(open(os.path.join(d, "summary.json")))
    for draw in (fig10, fig11_time, fig11_muscles, fig12, rolling):
        draw(d, s)
    print(f"plot_analysis: PNGs in {d}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
