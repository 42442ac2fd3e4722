# SPDX-License-Identifier: Apache-2.0
"""Reading the records runs write.

- Run records (CSV with a header, one row per recorded step): `tensegrity sim
  --telemetry` and `tensegrity hil --record`. Both name a cable's quantities
  `cableM_QUANTITY` (cable3_tension_n, cable3_rest_length_m); a HIL record written
  before the two shared one scheme named them `QUANTITY_M` (tension_n_3), and is
  read as well. The robot's centre is the record's centre_x_m/centre_y_m/centre_z_m
  when it has them (the HIL's), else the mean of its end caps' nodeI_x_m... (the
  simulator's), which is how the program computes it.
- Learning curves: `tensegrity evolve --log curve.csv`, one row per generation, and
  other tables of numbers (tools/ceiling.py's curve.csv).

A record that lacks a column or holds a cell that is not a number raises
RecordError naming the file, the line and the column; like program.RunError it is a
SystemExit, so a tool that does not catch it stops with that message.
"""
import csv
import math
import re

CABLE_COLUMN = re.compile(r"^cable(\d+)_(.+)$")
LEGACY_CABLE_COLUMN = re.compile(r"^(rest_length_m|length_m|tension_n|power_w)_(\d+)$")


class RecordError(SystemExit):
    """A record that cannot be read: the message names the file, line and column."""

    def __init__(self, message):
        super().__init__(message)
        self.message = message

    def __str__(self):
        return self.message


def cable_column(cable, quantity):
    """The column of one cable's quantity in a run record: cable3_tension_n."""
    return f"cable{cable}_{quantity}"


def number(text, path, line, column):
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise RecordError(f"{path}, line {line}: {column} {text!r} is not a number") from None
    return value


class Record:
    """A run record's rows (every `every`-th), as floats, with its columns by name."""

    def __init__(self, path, header, rows):
        self.path, self.header, self.rows = str(path), header, rows
        self.index = {}
        for i, name in enumerate(header):
            legacy = LEGACY_CABLE_COLUMN.match(name)
            self.index[cable_column(legacy.group(2), legacy.group(1)) if legacy else name] = i

    def has(self, column):
        return column in self.index

    def column(self, name):
        if name not in self.index:
            raise RecordError(f"{self.path}, line 1: no column {name}")
        i = self.index[name]
        return [row[i] for row in self.rows]

    def times_s(self):
        return self.column("time_s")

    def cable_count(self, quantity="tension_n"):
        """Cables whose `quantity` the record holds (cable0.. with no gap)."""
        m = 0
        while cable_column(m, quantity) in self.index:
            m += 1
        return m

    def cables(self, quantity):
        """Per row, every cable's `quantity` (cable 0 first)."""
        count = self.cable_count(quantity)
        if count == 0:
            raise RecordError(f"{self.path}, line 1: no column {cable_column(0, quantity)} "
                              f"(nor the older {quantity}_0)")
        columns = [self.index[cable_column(m, quantity)] for m in range(count)]
        return [[row[i] for i in columns] for row in self.rows]

    def node_count(self):
        n = 0
        while f"node{n}_x_m" in self.index:
            n += 1
        return n

    def centre_m(self):
        """Per row, the robot's centre (x, y, z): the record's centre columns, else the
        mean of its end caps."""
        if all(self.has(f"centre_{a}_m") for a in "xyz"):
            return list(zip(*(self.column(f"centre_{a}_m") for a in "xyz")))
        nodes = self.node_count()
        if nodes == 0:
            raise RecordError(f"{self.path}, line 1: no column centre_x_m nor node0_x_m: not a run record "
                              f"(`tensegrity sim --telemetry` or `tensegrity hil --record`)")
        axes = [[self.index[f"node{n}_{a}_m"] for n in range(nodes)] for a in "xyz"]
        return [tuple(sum(row[i] for i in axis) / nodes for axis in axes) for row in self.rows]

    def distance_m(self):
        """Per row, the horizontal distance of the centre from its first position."""
        centre = self.centre_m()
        if not centre:
            return []
        x0, y0 = centre[0][0], centre[0][1]
        return [math.hypot(x - x0, y - y0) for x, y, _ in centre]


def read_record(path, every=1):
    """A run record (`sim --telemetry`, `hil --record`), every `every`-th row."""
    if every < 1:
        raise RecordError(f"{path}: every {every}: must be at least 1")
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        if not header or "time_s" not in header:
            raise RecordError(f"{path}, line 1: no column time_s: not a run record")
        rows, cut, cut_cells = [], None, 0
        for n, row in enumerate(reader):
            line = n + 2
            if cut is not None:
                raise RecordError(f"{path}, line {cut}: cells missing ({cut_cells}, the header has {len(header)})")
            if len(row) != len(header):
                # A run stopped while writing leaves a cut last line: dropped. Anywhere
                # else a short line is damage.
                cut, cut_cells = line, len(row)
                continue
            if n % every == 0:
                rows.append([number(v, path, line, c) for v, c in zip(row, header)])
    return Record(path, header, rows)


def read_table(path, needed=(), what="a table of numbers"):
    """A CSV of numbers with a header (a learning curve of `evolve --log` or of
    tools/ceiling.py): one dict per row, every column a float. `needed`: columns it
    must have, else RecordError saying it is not `what`."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        missing = [c for c in needed if c not in (reader.fieldnames or [])]
        if missing:
            raise RecordError(f"{path}, line 1: no column {', '.join(missing)}: not {what}")
        rows = []
        for line, row in enumerate(reader, start=2):
            if None in row or None in row.values():
                raise RecordError(f"{path}, line {line}: {'more' if None in row else 'fewer'} cells than the "
                                  f"header's {len(reader.fieldnames)}")
            rows.append({k: number(v, path, line, k) for k, v in row.items()})
        return rows


def read_curve(path):
    """A learning curve (`evolve --log`): one dict per generation, every column a float."""
    return read_table(path, ("episodes", "best_so_far_m", "mean_score_m"),
                      "a learning curve (`tensegrity evolve --log`)")
