#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Plots a HIL run recorded with `tensegrity hil --record RUN.csv`: distance rolled
over time, and the mean and largest cable tension. Writes a PNG.

usage: tools/plot_run.py RUN.csv OUT.png [--title TEXT]
"""
import argparse
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv", help="per-tick CSV from tensegrity hil --record")
    parser.add_argument("png", help="output image")
    parser.add_argument("--title", default="SUPERball, 12 emulated end caps (HIL)")
    parser.add_argument("--every", type=int, default=10, help="plot every N-th row")
    args = parser.parse_args()

    t, dist, mean_t, max_t = [], [], [], []
    with open(args.csv, newline="") as f:
        reader = csv.reader(f)
        header = next(reader)
        try:
            ix, iy = header.index("centre_x_m"), header.index("centre_y_m")
        except ValueError:
            print(f"{args.csv}: not a HIL record (no centre_x_m/centre_y_m)", file=sys.stderr)
            return 2
        tension_cols = [i for i, name in enumerate(header) if name.startswith("tension_n_")]
        x0 = y0 = None
        for n, row in enumerate(reader):
            if n % args.every:
                continue
            x, y = float(row[ix]), float(row[iy])
            if x0 is None:
                x0, y0 = x, y
            tensions = [float(row[i]) for i in tension_cols]
            t.append(float(row[0]))
            dist.append(math.hypot(x - x0, y - y0))
            mean_t.append(sum(tensions) / len(tensions))
            max_t.append(max(tensions))
    if not t:
        print(f"{args.csv}: no rows", file=sys.stderr)
        return 2

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    ax1.plot(t, dist, color="tab:blue")
    ax1.set_ylabel("distance from start (m)")
    ax1.set_title(f"{args.title}: {dist[-1]:.2f} m in {t[-1]:.0f} s")
    ax1.grid(alpha=0.3)
    ax2.plot(t, mean_t, label="mean tension", color="tab:green")
    ax2.plot(t, max_t, label="largest tension", color="tab:red", linewidth=0.7)
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("tension (N)")
    ax2.legend(loc="upper right")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.png, dpi=110)
    print(f"plot: {args.png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
