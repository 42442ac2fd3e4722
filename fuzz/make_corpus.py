#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Writes the seed corpora of fuzz/ (corpus/<target>/): well-formed inputs of each
decoder, so the search starts from the formats' shapes instead of from nothing.
Deterministic; rerun after a format change. Usage: fuzz/make_corpus.py"""
import pathlib
import struct
import sys

import corpus_decoders

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent


def format_version():
    """msgs::kFormatVersion, read from its header: a seed with another version is
    refused at the first check, and the search would start behind it."""
    import re
    text = (ROOT / "msgs" / "format_version.hpp").read_text()
    return int(re.search(r"kFormatVersion = (\d+);", text).group(1))


def out(target, name, data):
    d = HERE / "corpus" / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data)


def can_v1(can_id, data, flags=0):
    return b"TCAN" + bytes([1, flags, len(data), 0]) + struct.pack("<I", can_id) + data.ljust(8, b"\0")


def can_v2(frames):
    body = b"".join(bytes([f, len(d), 0, 0]) + struct.pack("<I", i) + d.ljust(8, b"\0") for i, d, f in frames)
    return b"TCAN" + bytes([2, len(frames), 0, 0]) + body


def udp_can():
    frames = [
        (0x701, b"\x05", 0),                      # heartbeat, operational
        (0x701, b"\x00", 0),                      # boot-up
        (0x181, b"\x37\x06\x00\x10\x00\x00", 0),  # TPDO1: statusword + position
        (0x081, b"\x10\x81\x00\x00\x00\x00\x00\x00", 0),  # EMCY
        (0x581, b"\x60\x60\x60\x00\x00\x00\x00\x00", 0),  # SDO download response
        (0x080, b"", 0),                          # SYNC
        (0x1ABCDEF0, b"\x01\x02", 1),             # extended id
        (0x20, b"", 4),                           # error report
    ]
    for k, (i, d, f) in enumerate(frames):
        out("udp_can_datagram", f"v1-{k}", can_v1(i, d, f))
    out("udp_can_datagram", "v2-batch", can_v2(frames))
    # The same frames, one per input, feed the CANopen master target (its own layout
    # is FuzzedDataProvider's, so these only give it byte patterns to start from).
    for k, (i, d, _) in enumerate(frames):
        out("canopen_master", f"frame-{k}", b"\x01\x01\x00" + struct.pack("<I", i) + bytes([len(d)]) + d.ljust(8, b"\0"))


class Cdr:
    """Little-endian plain CDR (XCDR1), as Fast DDS 2.9 writes a sample."""

    def __init__(self):
        self.b = bytearray()

    def align(self, n):
        while len(self.b) % n:
            self.b.append(0)

    def put(self, fmt, v, n):
        self.align(n)
        self.b += struct.pack("<" + fmt, v)

    def u8(self, v): self.put("B", v, 1)
    def u16(self, v): self.put("H", v, 2)
    def i16(self, v): self.put("h", v, 2)
    def u32(self, v): self.put("I", v, 4)
    def i64(self, v): self.put("q", v, 8)
    def f64(self, v): self.put("d", v, 8)

    def string(self, s):
        raw = s.encode() + b"\0"
        self.u32(len(raw))
        self.b += raw

    def payload(self):
        return b"\x00\x01\x00\x00" + bytes(self.b)  # encapsulation CDR_LE


def policy_table(endcap, values, motors=2, complexity=5, version=1, force=False, seq=1):
    c = Cdr()
    c.u16(format_version()); c.u32(seq); c.i16(endcap); c.i16(endcap)
    c.string("superball-t4-n5"); c.u32(version); c.u8(1 if force else 0); c.string("superball")
    c.f64(4.0); c.f64(0.0); c.u32(motors); c.u32(complexity)
    c.u32(len(values))
    for v in values:
        c.f64(v)
    c.u32(0)  # checksum: the target fixes it up for half the inputs
    return c.payload()


def command(kind, seq=1, mask=0xFFF, start=0, issued=1_000_000_000, asked=900_000_000):
    c = Cdr()
    c.u16(format_version()); c.u32(seq); c.u8(kind); c.u16(mask); c.i64(start); c.i64(issued)
    for e in range(12):
        c.u32(0x5eed0000 + e if kind == 3 else 0)  # lives_seen: a clear-fault names what it saw
    for e in range(12):
        c.u32(e % 3 if kind == 3 else 0)  # estops_seen
    c.i64(asked if kind == 3 else 0)  # asked_host_time_ns: when the operator asked
    return c.payload()


def samples():
    table = [0.7, 0.8, 0.9, 1.0, 1.1, 0.95, 0.85, 0.75, 0.65, 1.05]
    out("policy_table_sample", "endcap0", policy_table(0, table))
    out("policy_table_sample", "endcap11-force", policy_table(11, table, force=True, version=7))
    out("policy_table_sample", "out-of-range", policy_table(3, [0.1] * 10))
    out("policy_table_sample", "one-motor-n2", policy_table(4, [0.7, 1.0], motors=1, complexity=2))
    for kind in range(5):
        out("command_sample", f"kind{kind}", command(kind, seq=kind + 1))


def files():
    for p in sorted((ROOT / "robots").glob("*.json")):
        out("robot_file", p.name, p.read_bytes())
    # Policy files are large (24 cables x n values); the two smallest shipped ones
    # are enough to seed the shapes.
    policies = sorted((ROOT / "policies").glob("*.json"), key=lambda p: p.stat().st_size)[:2]
    for p in policies:
        out("policy_file", p.name, p.read_bytes())
    out("endcap_config", "example.json", (ROOT / "firmware/endcap/endcap.example.json").read_bytes())


def operator_lines():
    """The operator console's socket (ground/operator_protocol.hpp): requests and a reply."""
    import json
    fmt = "tensegrity-operator/1"
    for name, command, mask, timeout in (("estop-all", "estop", 0xFFF, 30), ("stop-one", "stop", 0x8, 5),
                                         ("clear-some", "clear-fault", 0x5, 0.5)):
        line = {"format": fmt, "command": command, "endcap_mask": mask, "timeout_s": timeout}
        out("operator_request", name, json.dumps(line).encode())
    result = {"endcap": 3, "acked": True, "accepted": True, "reason": 0, "text": "accepted", "latency_s": 0.002}
    reply = {"format": fmt, "error": "", "console_pid": 12, "command": "estop", "rejoins": 0, "preempted": False,
             "results": [result]}
    out("operator_request", "reply-one", json.dumps(reply).encode())


def scenarios():
    """HIL fault scenarios (hil/scenario.hpp): files and --fault options, every fault
    named once, so each fault's parameter rules are in reach."""
    import json
    import re
    names = re.findall(r'\{FaultKind::\w+, "(\w+)"\}', (ROOT / "hil" / "scenario.cpp").read_text())
    params = {"drive_fault": {"motor": 1, "code": 0x2310, "release": True}, "drive_silent": {"motor": -1},
              "load_cell_drift": {"n_per_s": 5.0}, "drop_frames": {"probability": 0.2, "duration_s": 1.5},
              "corrupt_frames": {"probability": 0.1, "duration_s": 0, "kind": "datagram"},
              "release_spool": {"motor": 0}, "seize_spool": {"motor": 1}, "reboot_drive": {"motor": 0},
              "drive_preoperational": {"motor": 1}}
    events = []
    for k, name in enumerate(names):
        ev = {"time_s": 0.5 * k, "endcap": k % 12, "fault": name}
        if name in params:
            ev["params"] = params[name]
        events.append(ev)
    out("hil_scenario", "every-fault.json",
        json.dumps({"format": "tensegrity-hil-scenario/1", "events": events}, indent=1).encode())
    out("hil_scenario", "bare-list.json", json.dumps([{"time_s": 4.0, "fault": "cut_dds"}]).encode())
    for opt in ("3:drive_fault@2.0", "all:mute_dds@5", "11:restore_dds@0"):
        out("hil_scenario", "option-" + opt.replace(":", "-").replace("@", "-"), opt.encode())
    tokens = ['"{"', '"}"', '"["', '"]"', '":"', '","', '"@"', '"all"', '"true"', '"false"', '"null"', '"1e308"',
              '"-1"', '"4294967295"']
    keys = {"format", "events", "time_s", "endcap", "fault", "params", "frame", "datagram", "tensegrity-hil-scenario/1"}
    keys |= {p for d in params.values() for p in d}
    tokens += ['"\\"%s\\""' % k for k in sorted(keys | set(names))]
    tokens += ['"%s"' % n for n in names]  # a --fault option names its fault bare
    (HERE / "dict" / "hil_scenario.dict").write_text("# Generated by fuzz/make_corpus.py\n" + "\n".join(tokens) + "\n")


def json_keys(target):
    """Every key of the target's seed files, plus JSON's own tokens: libFuzzer
    splices these whole instead of discovering them a byte at a time."""
    import json
    keys = set()

    def walk(v):
        if isinstance(v, dict):
            for k, x in v.items():
                keys.add(k)
                walk(x)
        elif isinstance(v, list):
            for x in v:
                walk(x)
    for p in sorted((HERE / "corpus" / target).iterdir()):
        walk(json.loads(p.read_text()))
    tokens = ['"{"', '"}"', '"["', '"]"', '":"', '","', '"true"', '"false"', '"null"', '"1e308"', '"-0"', '"NaN"']
    tokens += ['"\\"%s\\""' % k for k in sorted(keys)]
    d = HERE / "dict"
    d.mkdir(exist_ok=True)
    (d / f"{target}.dict").write_text("# Generated by fuzz/make_corpus.py\n" + "\n".join(tokens) + "\n")


def dicts():
    for target in ("robot_file", "policy_file", "endcap_config", "operator_request", "endcap_stats",
                   "evolve_checkpoint"):
        json_keys(target)
    d = HERE / "dict"
    (d / "udp_can_datagram.dict").write_text('# Generated by fuzz/make_corpus.py\n"TCAN"\n"\\x01"\n"\\x02"\n')


if __name__ == "__main__":
    udp_can()
    samples()
    corpus_decoders.write_all(sys.modules[__name__])
    files()
    operator_lines()
    dicts()
    scenarios()
