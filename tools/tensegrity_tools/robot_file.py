# SPDX-License-Identifier: Apache-2.0
"""A robot file changed for one run (`--set PATH=JSON`, as in `tensegrity`'s own
robot overrides), written beside the run's results so the record says what it ran on."""
import json
import pathlib
import sys


def add_set_option(parser):
    parser.add_argument("--set", action="append", default=[], metavar="PATH=JSON",
                        help="change a robot field, e.g. strut.axial_damping_n_m_s=0.05 (repeatable)")


def set_field(doc, path, value_text):
    """doc with the field at dotted `path` set to the JSON `value_text`."""
    keys = path.split(".")
    node = doc
    for k in keys[:-1]:
        node = node.setdefault(k, {})
        if not isinstance(node, dict):
            sys.exit(f"--set {path}: {k} is not an object in the robot file")
    try:
        node[keys[-1]] = json.loads(value_text)
    except json.JSONDecodeError as e:
        sys.exit(f"--set {path}={value_text}: the value is not JSON ({e}); a string needs quotes: '\"text\"'")


def changed_robot(robot, sets):
    """The robot file at `robot` as a dict, with each `PATH=JSON` of `sets` applied."""
    doc = json.loads(pathlib.Path(robot).read_text())
    for item in sets:
        if "=" not in item:
            sys.exit(f"--set {item}: expected PATH=JSON")
        path, value = item.split("=", 1)
        set_field(doc, path, value)
    return doc


def write_robot(robot, sets, out):
    """OUT/robot.json: `robot` with `sets` applied. A run directory whose seeds
    already learned on another robot (a checkpoint under runs/) is refused."""
    out = pathlib.Path(out)
    path = out / "robot.json"
    text = json.dumps(changed_robot(robot, sets), indent=2) + "\n"
    if path.exists() and path.read_text() != text and any(out.glob("runs/s*/ckpt")):
        sys.exit(f"{path}: this arm's seeds learned on another robot; give the same --robot and --set "
                 f"to resume it, or a new --out")
    if not path.exists() or path.read_text() != text:
        path.write_text(text)
    return path
