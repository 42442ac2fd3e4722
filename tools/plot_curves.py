#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Plot learning curves from several CSV files on one axis, as PNG.

Each curve is LABEL=FILE:XCOLUMN:YCOLUMN[:XOFFSET] (XOFFSET is added to x), e.g.
  "coevolution, seed 1=out/experiments/runs/historical-t4-n5-e5000-s1/curve.csv:episodes:best_so_far_m"
  "CMA-ES from it=out/ceiling/from-shipped/curve.csv:evaluations:best_m:5000"
"""

import argparse
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from tensegrity_tools import runs  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    ap.add_argument("curves", nargs="+", metavar="LABEL=FILE:X:Y[:XOFFSET]")
    ap.add_argument("--out", required=True, help="PNG file")
    ap.add_argument("--title", default="")
    ap.add_argument("--xlabel", default="episodes (60 s each)")
    ap.add_argument("--ylabel", default="best distance so far, m in 60 s")
    ap.add_argument("--hline", type=float, action="append", default=[],
                    help="a horizontal reference line, e.g. the paper's 32 m")
    ap.add_argument("--legend-loc", default="best", help="matplotlib legend location, e.g. 'lower right'")
    a = ap.parse_args()

    fig, ax = plt.subplots(figsize=(8, 5))
    for spec in a.curves:
        label, _, rest = spec.rpartition("=")
        parts = rest.split(":")
        if len(parts) not in (3, 4):
            sys.exit(f"{spec}: expected LABEL=FILE:XCOLUMN:YCOLUMN[:XOFFSET]")
        path, xcol, ycol = parts[:3]
        try:
            offset = float(parts[3]) if len(parts) == 4 else 0.0
        except ValueError:
            sys.exit(f"{spec}: XOFFSET {parts[3]!r} is not a number")
        rows = runs.read_table(path, (xcol, ycol), f"a curve with columns {xcol} and {ycol}")
        ax.plot([r[xcol] + offset for r in rows], [r[ycol] for r in rows], label=label or path)
    for y in a.hline:
        ax.axhline(y, color="grey", linestyle="--", linewidth=1)
    ax.set_xlabel(a.xlabel)
    ax.set_ylabel(a.ylabel)
    ax.set_title(a.title)
    ax.grid(alpha=0.3)
    ax.legend(loc=a.legend_loc, fontsize="small")
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)


if __name__ == "__main__":
    main()
