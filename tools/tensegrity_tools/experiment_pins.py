# SPDX-License-Identifier: Apache-2.0
"""What every run in an experiments.py output directory must share besides its id: the
robot, and the evolve settings the program resolved. A run is found again by its
parameters alone, so a run made on another robot, or by a program whose defaults
changed (population sizes, step schedule), must not be taken for this one's."""
import json
import pathlib
import sys
import tempfile

from . import program


def pin_robot(a):
    """OUT/robot.json is the robot every run there learned on."""
    out = pathlib.Path(a.out)
    pinned, text = out / "robot.json", pathlib.Path(a.robot).read_text()
    if pinned.exists() and pinned.read_text() != text and any(out.glob("runs/*/summary.json")):
        sys.exit(f"experiments: the runs in {out} learned on the robot in {pinned}, not on {a.robot}; "
                 f"give that robot (--robot {pinned}) or a new --out")
    if not pinned.exists() or pinned.read_text() != text:
        pinned.write_text(text)


# What decides a run's result besides its id: `tensegrity evolve`'s defaults for these
# changed between versions (sizes, then the step schedule, then the robot's learning step
# and early end).
SETTINGS = ("population", "replace", "teams", "mutation", "sigma_m", "sigma_final_m", "anneal_start_episodes",
            "anneal_episodes", "dt_s", "early_end_bar_m", "early_end_speed_m_per_s")


def pin_settings(a):
    """OUT/evolve-settings.json holds the evolve settings every run there used, as the
    program resolved them. A one-episode probe asks this program what it would use, so
    that runs of another version's defaults are refused before hours are spent."""
    out = pathlib.Path(a.out)
    with tempfile.TemporaryDirectory() as tmp:
        try:
            probe = program.run(a.tensegrity, ["evolve", "--robot", a.robot, "--episodes", "1", "--duration", "0.01",
                                               "--period", "4", "--complexity", "2", "--threads", "1", "--out",
                                               f"{tmp}/p.json", "--log", f"{tmp}/c.csv", "--json"] + a.step_args)
        except program.RunError as e:
            sys.exit(f"experiments: tensegrity evolve refused the settings: {e}")
    config = probe.get("config", {})
    now = {k: config[k] for k in SETTINGS if k in config}
    # Keyed by the runs' step tag: runs with their own step options have their own ids.
    pinned, tag = out / "evolve-settings.json", a.mutation_tag or "default"
    try:
        table = json.loads(pinned.read_text()) if pinned.exists() else {}
    except json.JSONDecodeError as e:
        sys.exit(f"experiments: {pinned} is not JSON ({e}); restore it from git or give a new --out")
    # A tag ends its runs' ids; "-m0.05" must not claim the runs of "-m0.05-0.02-3000".
    mine = [d for d in out.glob("runs/*/summary.json")
            if (d.parent.name.endswith(a.mutation_tag) if a.mutation_tag else "-m" not in d.parent.name)]
    if tag in table and mine:
        changed = [f"{k}: {table[tag].get(k)} -> {now.get(k)}" for k in SETTINGS if table[tag].get(k) != now.get(k)]
        if changed:
            sys.exit(f"experiments: the runs in {out} used other evolve settings ({pinned}): {', '.join(changed)}; "
                     f"build the version they were made with, or give a new --out")
    table[tag] = now
    pinned.write_text(json.dumps(table, indent=2, sort_keys=True) + "\n")
