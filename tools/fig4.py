#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""The paper's Figure 4 on a robot file: pull one muscle, see how every length moves.

Plays two episodes from the settled start with `tensegrity sim --telemetry` (the
firmware's control core on the ODE model): every cable held at the robot's initial
rest length, and the same with one cable (--cable) driven to --rest-length at the
motor's speed. Each cable's actual length is averaged over the last --average-s
seconds of each episode; a cable whose length changes by more than --tolerance-m
shortened or lengthened. The paper (Iscen et al., Figure 4; muscle 13 pulled to 0.5 m):
"the lengths of all the muscles change; some of them increase while others decrease".

When --rest-length lies below the robot's shortest rest length (the paper's 0.5 m
against the hardware's 0.6 m), the tool writes a copy of the robot with
cable.min_rest_length_m lowered to it (OUT/robot.json), since the motor clamps to it.

Writes, in OUT:
  fig4_pull.csv    cable, owner end cap, held and pulled length, change, verdict
  fig4_pull.png    grey bars held, red bars pulled (as the paper's figure)
  fig4_pull.json   counts of cables that shortened / lengthened, how far the robot moved
  fig4_every_cable.csv   with --every-cable: the counts for each cable pulled in turn
                   (the paper does not say how its muscles are numbered)

  tools/fig4.py --out out/fig4 --robot robots/superball-paper.json --every-cable
"""
import argparse
import csv
import json
import pathlib
import statistics
import sys

from tensegrity_tools import program, robot_file, runs


def parse_args(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", required=True, help="output directory")
    program.add_option(p)
    p.add_argument("--robot", default=str(program.ROOT / "robots/superball-paper.json"), help="robot description")
    robot_file.add_set_option(p)
    p.add_argument("--cable", type=int, default=3,
                   help="the cable pulled, 0-based (default: %(default)s, the 13th muscle of the author's NTRT model, "
                        "mapped onto this file's nodes: docs/design/model.md)")
    p.add_argument("--rest-length", type=float, default=0.5, help="its rest length, m (default: %(default)s)")
    p.add_argument("--duration", type=float, default=10.0, help="episode length, s (default: %(default)s)")
    p.add_argument("--average-s", type=float, default=1.0,
                   help="average lengths over the episode's last seconds (default: %(default)s)")
    p.add_argument("--every-cable", action="store_true",
                   help="also pull each cable in turn and count, per pull, the others that shortened")
    p.add_argument("--tolerance-m", type=float, default=0.001,
                   help="a change smaller than this is 'same' (default: %(default)s)")
    a = p.parse_args(argv)
    if not pathlib.Path(a.robot).is_file():
        p.error(f"--robot {a.robot}: no such file")
    if a.rest_length <= 0.0:
        p.error(f"--rest-length {a.rest_length}: must be positive")
    if not 0.0 < a.average_s < a.duration:
        p.error(f"--average-s {a.average_s}: must be positive and shorter than --duration {a.duration}")
    return a


def hold_policy(robot_doc, pulled=None, rest_length=None):
    """A one-value table: every cable at the initial rest length, one of them at rest_length."""
    start = robot_doc["cable"]["initial_rest_length_m"]
    cables = [{"cable": i, "owner": c["owner"], "rest_lengths_m": [rest_length if i == pulled else start]}
              for i, c in enumerate(robot_doc["cables"])]
    return {"format": "tensegrity-policy/1", "robot": robot_doc["name"], "period_s": 4.0, "complexity": 1,
            "cables": cables, "provenance": {"method": "hand", "created_by": "tools/fig4.py"}}


def play(a, robot, policy_path, telemetry):
    return program.sim(a.tensegrity, policy_path, robot, ["--start", "settled", "--duration", f"{a.duration:g}",
                                                          "--telemetry", telemetry, "--telemetry-every", "10"])


def mean_lengths(telemetry, cables, from_s):
    """Each cable's actual length averaged over the rows at or after from_s."""
    record = runs.read_record(telemetry)
    if record.cable_count("length_m") != cables:
        sys.exit(f"{telemetry}: {record.cable_count('length_m')} cables' lengths, the robot has {cables}")
    late = [lengths for t, lengths in zip(record.times_s(), record.cables("length_m")) if t + 1e-9 >= from_s]
    if not late:
        sys.exit(f"{telemetry}: no rows in the last {from_s} s")
    return [sum(column) / len(late) for column in zip(*late)]


def verdict(change_m, tolerance_m):
    return "shortened" if change_m < -tolerance_m else "lengthened" if change_m > tolerance_m else "same"


def plot(path, rows, a):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    x = [r["cable"] for r in rows]
    fig, ax = plt.subplots(figsize=(10, 4))
    ax.bar([i - 0.2 for i in x], [r["held_length_m"] for r in rows], 0.4, color="0.6", label="all held")
    ax.bar([i + 0.2 for i in x], [r["pulled_length_m"] for r in rows], 0.4, color="tab:red",
           label=f"cable {a.cable} pulled to {a.rest_length:g} m")
    ax.set_xticks(x)
    ax.set_xlabel("cable")
    ax.set_ylabel("actual length, m")
    ax.set_title(f"Figure 4 on {pathlib.Path(a.robot).name}: one muscle pulled")
    ax.legend(loc="lower right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def pull(a, robot, robot_doc, cable, held):
    """Play the table with `cable` pulled; its rows against the held lengths, and the sim's summary."""
    out = pathlib.Path(a.out)
    tag = f"pulled{cable}"
    path = out / f"{tag}-policy.json"
    path.write_text(json.dumps(hold_policy(robot_doc, cable, a.rest_length), indent=2) + "\n")
    result = play(a, robot, path, out / f"{tag}-telemetry.csv")
    lengths = mean_lengths(out / f"{tag}-telemetry.csv", len(held), a.duration - a.average_s)
    if cable != a.cable:  # the other pulls keep their counts, not 24 telemetry files
        (out / f"{tag}-telemetry.csv").unlink()
        path.unlink()
    rows = [{"cable": i, "owner": c["owner"], "held_length_m": held[i], "pulled_length_m": lengths[i],
             "change_m": lengths[i] - held[i]} for i, c in enumerate(robot_doc["cables"])]
    for r in rows:
        r["verdict"] = verdict(r["change_m"], a.tolerance_m)
    others = [r for r in rows if r["cable"] != cable]
    counts = {"cable": cable, "pulled_cable_change_m": rows[cable]["change_m"],
              "others_shortened": sum(r["verdict"] == "shortened" for r in others),
              "others_lengthened": sum(r["verdict"] == "lengthened" for r in others),
              "others_same": sum(r["verdict"] == "same" for r in others),
              "others_change_median_abs_m": statistics.median(abs(r["change_m"]) for r in others),
              "moved_m": result["distance_m"], "max_tension_n": result["max_tension_n"]}
    return rows, counts


def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def every_cable(a, robot, robot_doc, held, counts):
    """Pull each cable in turn (`counts`: --cable's, already played): the paper's muscle
    numbering need not be this robot's."""
    table = [counts if c == a.cable else pull(a, robot, robot_doc, c, held)[1] for c in range(len(held))]
    write_csv(pathlib.Path(a.out) / "fig4_every_cable.csv", table)
    shortened = [t["others_shortened"] for t in table]
    return {"cables_pulled": len(table), "others_shortened_median": statistics.median(shortened),
            "others_shortened_min": min(shortened), "others_shortened_max": max(shortened),
            "pulls_with_some_shortened": sum(1 for n in shortened if n > 0),
            "pulls_with_some_lengthened": sum(1 for t in table if t["others_lengthened"] > 0)}


def main(argv=None):
    a = parse_args(argv)
    out = pathlib.Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    doc = json.loads(pathlib.Path(a.robot).read_text())
    try:  # the fields this tool reads before `tensegrity sim` validates the whole file
        cables = len(doc["cables"])
        shortest, longest = doc["cable"]["min_rest_length_m"], doc["cable"]["max_rest_length_m"]
        doc["cable"]["initial_rest_length_m"]
    except (KeyError, TypeError) as e:
        sys.exit(f"--robot {a.robot}: missing field {e} (cables, cable.min_rest_length_m, "
                 f"cable.max_rest_length_m, cable.initial_rest_length_m)")
    if not 0 <= a.cable < cables:
        sys.exit(f"--cable {a.cable}: the robot has cables 0-{cables - 1}")
    if a.rest_length > longest:
        sys.exit(f"--rest-length {a.rest_length:g}: above the robot's longest rest length "
                 f"(cable.max_rest_length_m {longest:g})")
    if a.rest_length < shortest:
        a.set = a.set + [f"cable.min_rest_length_m={a.rest_length}"]
    a.tensegrity = program.find(a.tensegrity)
    robot = robot_file.write_robot(a.robot, a.set, out)
    robot_doc = json.loads(robot.read_text())
    (out / "held-policy.json").write_text(json.dumps(hold_policy(robot_doc), indent=2) + "\n")
    held_result = play(a, robot, out / "held-policy.json", out / "held-telemetry.csv")
    held = mean_lengths(out / "held-telemetry.csv", cables, a.duration - a.average_s)
    rows, counts = pull(a, robot, robot_doc, a.cable, held)
    write_csv(out / "fig4_pull.csv", rows)
    summary = {"robot": str(a.robot), "set": a.set, "rest_length_m": a.rest_length, "duration_s": a.duration,
               "tolerance_m": a.tolerance_m, **counts, "held_moved_m": held_result["distance_m"],
               "held_max_tension_n": held_result["max_tension_n"], "held_mean_tension_n": held_result["mean_tension_n"],
               # a slack cable at rest means the structure does not hold its shape (collapsed)
               "held_slack_cables": sum(1 for x in held if x <= robot_doc["cable"]["initial_rest_length_m"])}
    if a.every_cable:
        summary["every_cable"] = every_cable(a, robot, robot_doc, held, counts)
    (out / "fig4_pull.json").write_text(json.dumps(summary, indent=2) + "\n")
    plot(out / "fig4_pull.png", rows, a)
    print(f"cable {a.cable} to {a.rest_length:g} m: its length changed {counts['pulled_cable_change_m']:+.3f} m; "
          f"of the other {cables - 1}, {counts['others_shortened']} shortened, {counts['others_lengthened']} "
          f"lengthened, {counts['others_same']} kept their length (|change| < {a.tolerance_m:g} m); "
          f"the robot moved {counts['moved_m']:.3f} m (held: {held_result['distance_m']:.3f} m)")
    if a.every_cable:
        e = summary["every_cable"]
        print(f"each of the {e['cables_pulled']} cables pulled in turn: others shortened median "
              f"{e['others_shortened_median']:g} (min {e['others_shortened_min']}, max {e['others_shortened_max']}); "
              f"{e['pulls_with_some_shortened']} pulls shortened some and "
              f"{e['pulls_with_some_lengthened']} lengthened some")


if __name__ == "__main__":
    main()
