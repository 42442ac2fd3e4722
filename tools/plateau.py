#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""What the seeds of an arm that stay on the plateau play, and how the others left it.

For every finished seed of one or more arms (tools/arm.py's OUT/runs/sK/, or OUT/sK/),
two readings:
- its best gait, played once by `tensegrity analyze` on the arm's robot.json: distance,
  revolutions and the turn period, the ground faces it visits (how many, how often it
  steps back to the face before last, whether they settle into a cycle), end caps on
  the ground, tension, power, strut spin;
- its take-off, from curve.csv: the first generation whose best team reaches
  --takeoff-m, the best team before it, the generation's mean score then, and the
  episode of the first team >= --roll-m.

A seed rolls if its best gait reaches --roll-m, is on the plateau if it stays below
--takeoff-m, and is late otherwise.

Writes OUT/plateau.csv (a row per seed), OUT/plateau.json (per class and for the
take-offs: medians and counts) and OUT/plateau.png (distance against revolutions;
the take-off jumps); prints a readable table.

Example:
  tools/plateau.py /work/arms/pop30-paper /work/arms/pop20-paper --out out/plateau
"""
import argparse
import csv
import json
import pathlib
import statistics
import sys

from tensegrity_tools import program, runs

FIELDS = ["arm", "seed", "class", "distance_m", "revolutions", "turn_period_s", "contact_period_s", "faces",
          "distinct_faces", "back_steps", "face_cycle_match", "endcaps_on_ground", "mean_tension_n",
          "max_tension_n", "power_w", "axial_spin_rms_rad_s", "takeoff_episode", "best_before_takeoff_m",
          "best_at_takeoff_m", "generation_mean_at_takeoff_m", "first_roll_episode"]


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter, epilog=__doc__)
    p.add_argument("arms", nargs="+", help="arm directories written by tools/arm.py")
    p.add_argument("--out", required=True, help="directory for plateau.csv, plateau.json, plateau.png")
    program.add_option(p)
    p.add_argument("--takeoff-m", type=float, default=20.0, help="a best team this far has left the plateau")
    p.add_argument("--roll-m", type=float, default=28.0, help="a gait this far rolls (the issue's 28 m)")
    p.add_argument("--duration", type=float, default=60.0, help="episode length of the replay, s")
    return p.parse_args()


def seeds_of(arm):
    found = sorted(arm.glob("runs/s*")) or sorted(arm.glob("s*"))
    return [d for d in found if (d / "policy.json").exists() and (d / "curve.csv").exists()]


def gait(a, arm, run):
    d = program.run(a.tensegrity, ["analyze", run / "policy.json", "--robot", arm / "robot.json", "--duration",
                                   a.duration, "--out", pathlib.Path(a.out) / "analyze" / arm.name / run.name,
                                   "--no-plots", "--json"])
    e, ro, period = d["episode"], d["rolling"], d["revolution_period_s"]
    faces = [tuple(f) for f in ro["face_sequence"]]
    # The analyzer gives 0 for a period it cannot measure (a gait that never turns): none.
    return {"distance_m": e["distance_m"], "revolutions": ro["revolutions"], "turn_period_s": period["rotation"] or None,
            "contact_period_s": period["contacts"] or None, "faces": len(faces), "distinct_faces": len(set(faces)),
            "back_steps": sum(1 for i in range(2, len(faces)) if faces[i] == faces[i - 2]),
            "face_cycle_match": ro["face_cycle_match"], "endcaps_on_ground": e["endcaps_touched_ground"],
            "mean_tension_n": e["mean_tension_n"], "max_tension_n": e["max_tension_n"],
            "power_w": e["mean_motor_power_w"], "axial_spin_rms_rad_s": e["axial_spin_rms_rad_per_s"]}


def takeoff(a, curve_csv):
    out = {k: None for k in FIELDS[-5:]}
    before = 0.0
    for r in runs.read_curve(curve_csv):
        best, mean = r["best_so_far_m"], r["mean_score_m"]
        if best >= a.takeoff_m and out["takeoff_episode"] is None:
            out.update(takeoff_episode=int(r["episodes"]), best_before_takeoff_m=before, best_at_takeoff_m=best,
                       generation_mean_at_takeoff_m=mean)
        if best >= a.roll_m and out["first_roll_episode"] is None:
            out["first_roll_episode"] = int(r["episodes"])
        before = best
    return out


def median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def summarise(a, rows):
    classes = {}
    for c in ("rolls", "late", "plateau"):
        group = [r for r in rows if r["class"] == c]
        classes[c] = {"seeds": len(group), **{f"median_{k}": median([r[k] for r in group]) for k in FIELDS[3:16]},
                      "face_cycle_seeds": sum(1 for r in group if r["face_cycle_match"] >= 0.8)}
    left = [r for r in rows if r["takeoff_episode"] is not None]
    jumps = {"seeds": len(left), "median_best_before_m": median([r["best_before_takeoff_m"] for r in left]),
             "median_best_at_m": median([r["best_at_takeoff_m"] for r in left]),
             "median_generation_mean_m": median([r["generation_mean_at_takeoff_m"] for r in left]),
             "max_generation_mean_m": max((r["generation_mean_at_takeoff_m"] for r in left), default=None),
             "rolling_in_the_same_generation": sum(1 for r in left if r["first_roll_episode"] == r["takeoff_episode"]),
             "median_episodes_takeoff_to_roll": median([r["first_roll_episode"] - r["takeoff_episode"]
                                                        for r in left if r["first_roll_episode"] is not None])}
    return {"arms": [str(x) for x in a.arms], "takeoff_m": a.takeoff_m, "roll_m": a.roll_m, "classes": classes,
            "takeoffs": jumps}


def plot(a, rows):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("plateau: matplotlib missing (Debian: python3-matplotlib): no plot", file=sys.stderr)
        return
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    colours = {"rolls": "tab:green", "late": "tab:orange", "plateau": "tab:red"}
    for c, colour in colours.items():
        group = [r for r in rows if r["class"] == c]
        left.scatter([r["revolutions"] for r in group], [r["distance_m"] for r in group], c=colour, label=c, s=22)
    left.set(xlabel=f"revolutions in {a.duration:g} s", ylabel="distance, m", title="best gait of each seed")
    left.legend()
    taken = [r for r in rows if r["takeoff_episode"] is not None]
    for r in taken:
        right.plot([r["takeoff_episode"]] * 2, [r["best_before_takeoff_m"], r["best_at_takeoff_m"]], c="tab:blue", lw=1)
    right.scatter([r["takeoff_episode"] for r in taken], [r["generation_mean_at_takeoff_m"] for r in taken],
                  c="tab:gray", s=14, label="generation mean then")
    right.axhline(a.roll_m, ls=":", c="k", lw=0.8)
    right.set(xlabel="episode of the take-off generation", ylabel="m",
              title=f"take-off: best team before -> first >= {a.takeoff_m:g} m")
    right.legend()
    fig.tight_layout()
    fig.savefig(pathlib.Path(a.out) / "plateau.png", dpi=110)


def main():
    a = parse_args()
    a.tensegrity = program.find(a.tensegrity)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for arm in (pathlib.Path(x) for x in a.arms):
        if not (arm / "robot.json").exists():
            sys.exit(f"plateau: {arm}: no robot.json (not an arm written by tools/arm.py)")
        runs = seeds_of(arm)
        if not runs:
            sys.exit(f"plateau: {arm}: no finished seed (runs/sK/policy.json and curve.csv)")
        for run in runs:
            print(f"plateau: {arm.name}/{run.name}", file=sys.stderr)
            row = {"arm": arm.name, "seed": run.name, **gait(a, arm, run), **takeoff(a, run / "curve.csv")}
            d = row["distance_m"]
            row["class"] = "rolls" if d >= a.roll_m else "plateau" if d < a.takeoff_m else "late"
            rows.append(row)
    with open(out / "plateau.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    summary = summarise(a, rows)
    (out / "plateau.json").write_text(json.dumps(summary, indent=2) + "\n")
    plot(a, rows)
    print(f"{'arm':<14} {'seed':<5} {'class':<8} {'m':>5} {'revs':>5} {'turn s':>6} {'faces':>5} {'back':>4} "
          f"{'cycle':>5} {'caps':>4} {'take-off':>8} {'from->to m':>12} {'gen mean':>8}")
    for r in rows:
        jump = (f"{r['best_before_takeoff_m']:.1f}->{r['best_at_takeoff_m']:.1f}" if r["takeoff_episode"] else "-")
        mean = f"{r['generation_mean_at_takeoff_m']:.1f}" if r["takeoff_episode"] else "-"
        print(f"{r['arm']:<14} {r['seed']:<5} {r['class']:<8} {r['distance_m']:5.1f} {r['revolutions']:5.2f} "
              f"{r['turn_period_s'] or 0:6.1f} {r['distinct_faces']:5d} {r['back_steps']:4d} {r['face_cycle_match']:5.2f} "
              f"{r['endcaps_on_ground']:4d} {r['takeoff_episode'] or '-':>8} {jump:>12} {mean:>8}")
    print(json.dumps(summary, indent=2))


if __name__ == "__main__":
    main()
