#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Plots a run record (`tensegrity hil --record RUN.csv` or `tensegrity sim --telemetry
RUN.csv`, also a HIL record of an older version): distance rolled over time, and the
mean and largest cable tension. Writes a PNG.

usage: tools/plot_run.py RUN.csv OUT.png [--title TEXT] [--every N]
"""
import argparse
import sys

from tensegrity_tools import runs


def read(path, every):
    """Times, distances from the start, mean and largest tension, every `every`-th row."""
    record = runs.read_record(path, every)
    if not record.rows:
        raise runs.RecordError(f"{path}: no rows")
    tensions = record.cables("tension_n")
    return (record.times_s(), record.distance_m(), [sum(t) / len(t) for t in tensions],
            [max(t) for t in tensions])


def plot(png, title, t, dist, mean_t, max_t):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    ax1.plot(t, dist, color="tab:blue")
    ax1.set_ylabel("distance from start (m)")
    ax1.set_title(f"{title}: {dist[-1]:.2f} m in {t[-1]:.0f} s")
    ax1.grid(alpha=0.3)
    ax2.plot(t, mean_t, label="mean tension", color="tab:green")
    ax2.plot(t, max_t, label="largest tension", color="tab:red", linewidth=0.7)
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("tension (N)")
    ax2.legend(loc="upper right")
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("csv", help="run record: tensegrity hil --record, or tensegrity sim --telemetry")
    parser.add_argument("png", help="output image")
    parser.add_argument("--title", default="SUPERball, 12 emulated end caps (HIL)")
    parser.add_argument("--every", type=int, default=10, help="plot every N-th row")
    args = parser.parse_args()
    if args.every < 1:
        parser.error(f"--every {args.every}: must be at least 1")
    try:
        plot(args.png, args.title, *read(args.csv, args.every))
    except runs.RecordError as e:
        print(f"plot_run: {e}", file=sys.stderr)
        return 2
    print(f"plot: {args.png}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
