# SPDX-License-Identifier: Apache-2.0
"""Seed corpora of the decoders behind the wire and the files (fuzz/make_corpus.py
calls write_all with itself, for its helpers: out, Cdr, command, format_version, ROOT):
the command gate, the end cap's time sync, the ground's samples, the replay CSV, the
policy store, the stats file, evolution checkpoints and the MPI messages."""
import struct

M = None  # fuzz/make_corpus.py, set by write_all


def out(target, name, data):
    M.out(target, name, data)


def Cdr():
    return M.Cdr()


def command(*args, **kwargs):
    return M.command(*args, **kwargs)


def format_version():
    return M.format_version()


def gate_runs():
    """Runs of commands into one end cap's gate: header (end cap 3, synced, host
    time 1.5 s, life id), then per sample writer byte, u16 length, payload."""
    def run(commands, synced=1):
        head = bytes([3, synced]) + struct.pack("<qI", 1_500_000_000, 0x5eed0003)
        return head + b"".join(bytes([w]) + struct.pack("<H", len(c)) + c for w, c in commands)
    out("command_gate", "start-stop", run([(0, command(0, seq=1)), (0, command(1, seq=2))]))
    out("command_gate", "estop-then-late-clear", run([(1, command(2, seq=7)), (2, command(3, seq=3)),
                                                       (1, command(3, seq=8))]))
    out("command_gate", "repeat-and-reorder", run([(0, command(1, seq=5)), (0, command(1, seq=5)),
                                                    (0, command(1, seq=4))]))
    out("command_gate", "unsynced-start", run([(3, command(0, seq=0xFFFFFFFF)), (3, command(0, seq=0))], synced=0))
    out("command_gate", "not-addressed", run([(0, command(1, mask=0x4))]))


def heartbeat(source=-1, heard=0xFFF, life=0, estops=0):
    c = Cdr()
    c.u16(format_version()); c.i16(source); c.u32(9); c.i64(2_000_000_000); c.u8(0); c.u8(0)
    c.string(""); c.u32(0); c.u8(1); c.i64(0); c.i64(0); c.u8(0); c.u8(1); c.i64(0)
    c.u16(heard); c.u32(life); c.u32(estops)
    return c.payload()


def time_sync_reply(nonce, t1, t2, t3, endcap=3):
    c = Cdr()
    c.u16(format_version()); c.i16(endcap); c.u32(1); c.put("Q", nonce, 8); c.i64(t1); c.i64(t2); c.i64(t3)
    return c.payload()


def time_sync_runs():
    """The end cap's host heartbeat, and runs of time-sync events: op byte (bits
    0-1: 0 request, 1 reply, 2-3 settle; a reply with bit 7 set echoes the nonce of
    request slot bits 2-4), u16 time step in us, for a reply a length byte and the
    sample."""
    out("endcap_time_sync", "host-heartbeat", b"\x00" + heartbeat())
    reply = time_sync_reply(0, 1_000_000_000, 5_000_000_000, 5_000_100_000)
    ops = b""
    for k in range(3):
        ops += b"\x00" + struct.pack("<H", 1000)                                       # request
        ops += bytes([0x81 | (k << 2)]) + struct.pack("<H", 2000) + bytes([len(reply)]) + reply
    ops += (b"\x02" + struct.pack("<H", 65000)) * 10  # settle: past max_round_trip + max_host_hold
    out("endcap_time_sync", "three-exchanges", b"\x01" + ops)
    out("endcap_time_sync", "unknown-nonce", b"\x01\x01\x10\x00" + bytes([len(reply)]) + reply)


def telemetry(endcap, seq, fault=0):
    c = Cdr()
    c.u16(format_version()); c.i16(endcap); c.u32(seq); c.i64(5_000_000_000); c.i64(4_000_000_000)
    c.put("Q", 4000, 8); c.u8(2); c.u8(fault); c.u32(2); c.u32(3); c.u8(0); c.u8(1)
    for v in (0.9, 1.0, 0, 0, 0.91, 0.99, 0, 0, 120.0, 95.5, 0, 0):
        c.f64(v)
    c.put("Q", 0, 8); c.string("superball-t4-n5"); c.u32(3)
    return c.payload()


def command_ack(endcap, seq, life, estops, reason=0):
    c = Cdr()
    c.u16(format_version()); c.i16(endcap); c.u32(seq); c.u8(1 if reason == 0 else 0); c.u8(reason)
    c.string("accepted" if reason == 0 else "estop_unseen"); c.u32(life); c.u32(estops)
    return c.payload()


def policy_ack(endcap):
    c = Cdr()
    c.u16(format_version()); c.i16(endcap); c.u32(4); c.u8(1); c.u8(0); c.string("accepted")
    c.string("superball-t4-n5"); c.u32(3); c.u32(0xC0FFEE)
    return c.payload()


def ground_runs():
    """What a ground tool hears (ground/station_samples.hpp): per sample a type byte
    (0 telemetry, 1 heartbeat, 2 command ack, 3 policy ack), u16 length, payload."""
    def run(samples):
        return b"".join(bytes([t]) + struct.pack("<H", len(p)) + p for t, p in samples)
    out("ground_samples", "telemetry-gap", run([(0, telemetry(3, 1)), (0, telemetry(3, 5, fault=9))]))
    out("ground_samples", "heartbeat-then-acks", run([(1, heartbeat(source=0, life=0x5eed, estops=1)),
                                                       (2, command_ack(0, 7, 0x5eed, 2)),
                                                       (3, policy_ack(0))]))
    out("ground_samples", "new-life-then-stale", run([(2, command_ack(5, 1, 11, 4)), (2, command_ack(5, 2, 12, 0)),
                                                       (2, command_ack(5, 3, 11, 9, reason=9))]))


def replay_csvs():
    """Telemetry CSVs for the view's replay (view/replay_data.hpp), for the shipped robot:
    `tensegrity sim --telemetry`'s spelling with energies, and the older HIL records' spelling
    (tension_n_3 for cable3_tension_n, still read) without."""
    import json
    robot = json.loads((M.ROOT / "robots" / "superball.json").read_text())
    nodes, cables = len(robot["nodes_m"]), len(robot["cables"])
    node_cols = [f"node{n}_{a}_m" for n in range(nodes) for a in "xyz"]

    def rows(count, width):
        return "".join(",".join([f"{0.01 * k:.2f}"] + [f"{0.5 + 0.001 * (k + c):.4f}" for c in range(width)]) + "\n"
                       for k in range(count))
    sim_cols = node_cols + [f"cable{m}_rest_length_m" for m in range(cables)]
    sim_cols += [f"cable{m}_tension_n" for m in range(cables)] + ["kinetic_energy_j", "gravity_energy_j",
                                                                   "elastic_energy_j"]
    out("replay_csv", "sim.csv", ("time_s," + ",".join(sim_cols) + "\n" + rows(5, len(sim_cols))).encode())
    hil_cols = node_cols + [f"rest_length_m_{m}" for m in range(cables)] + [f"tension_n_{m}" for m in range(cables)]
    text = "time_s," + ",".join(hil_cols) + "\n" + rows(3, len(hil_cols))
    out("replay_csv", "hil-cut-last-line.csv", (text + "0.05,0.5,0.").encode())


def stored_table(generation=3, motors=2, complexity=2, period=4.0, values=(0.8, 0.9, 1.0, 0.95), ident=b"t4-n2",
                 version=2):
    body = struct.pack("<QIIdd", generation, motors, complexity, period, 0.0)
    body += b"".join(struct.pack("<d", v) for v in values)
    if version == 1:
        return b"ETB1" + body
    return b"ETB2" + body + struct.pack("<III", 7, 0xC0FFEE, len(ident)) + ident


def store_records():
    """The policy store (firmware/app/policy_store.hpp): a whole blob file (mode byte
    0: "TBLB", version, length, CRC-32, payload) or two slots' payloads (mode 5,
    split byte: slot a is bytes 1..split*4 after it)."""
    import zlib
    new, old = stored_table(), stored_table(generation=2, version=1)
    blob = b"TBLB" + struct.pack("<III", 1, len(new), zlib.crc32(new)) + new
    out("policy_store_record", "file-etb2", b"\x00" + blob)
    out("policy_store_record", "file-bad-crc", b"\x00" + blob[:12] + b"\0\0\0\0" + new)
    split = (len(new) + 1 + 3) // 4
    slot_a = new.ljust(split * 4 - 1, b"\0")
    out("policy_store_record", "two-slots", b"\x05" + bytes([split]) + slot_a + old)
    out("policy_store_record", "one-slot-etb1", b"\x01\x40" + old)
    out("policy_store_record", "out-of-limits", b"\x01\x40" + stored_table(values=(0.1, 0.2, 3.0, 0.9)))


def endcap_stats():
    import json
    timing = {"count": 60000, "p50_us": 12.5, "p99_us": 80.0, "max_us": 410.0}
    stats = {"format": "tensegrity-endcap-stats/2", "final": True, "endcap": 3, "mode": "realtime",
             "rate_hz": 1000.0, "cycles": 60000, "overruns": 2, "stalls": 0, "late_wakeups": 1,
             "syncs_received": 0, "send_failures": 0, "rx_drops": 0, "drain_limited_cycles": 0,
             "fault": "none", "bring_up": "done", "vm_rss_kb": 21000,
             "link": {"host_losses": 1, "host_returns": 1, "link_cuts": 0, "loop_stalls": 0, "rejoins": 0},
             "cycle": timing, "wakeup_latency": timing,
             "table": {"period_s": 4.0, "loop_time_ns": 5_000_000_000, "table_time_ns": 1_000_000_000,
                       "origin_loop_ns": 4_000_000_000, "loop_clock_origin_ns": 123}}
    out("endcap_stats", "final.json", json.dumps(stats, indent=1).encode())
    snapshot = dict(stats, final=False, cycle=None, wakeup_latency=None, table=None, mode="lockstep")
    out("endcap_stats", "snapshot.json", json.dumps(snapshot).encode())


def mt19937_64_state(seed):
    """std::mt19937_64's text form right after seeding: its 312 words (the
    standard's initialisation), then libstdc++'s position in them, as operator<<
    writes them."""
    x = [seed & (2**64 - 1)]
    for i in range(1, 312):
        x.append((6364136223846793005 * (x[-1] ^ (x[-1] >> 62)) + i) & (2**64 - 1))
    return " ".join(str(v) for v in x + [312])


def checkpoints():
    import json
    config = {"method": "leniency", "population": 4, "teams": 8, "replace": 2, "mutation": "gaussian",
              "sigma_m": 0.05, "sigma_final_m": 0.05, "anneal_start_episodes": 0, "anneal_episodes": 0,
              "seed": 1, "episodes": 1000, "cables": 2, "complexity": 2, "min_rest_length_m": 0.6,
              "max_rest_length_m": 1.1, "period_s": 4.0, "duration_s": 10.0, "robot_name": "superball",
              "robot_hash": "0" * 16}
    member = {"rest_lengths_m": [0.8, 0.9], "history": [1.5, 2.0]}
    stats = {"generation": 1, "episodes": 8, "teams": 8, "infeasible": 0, "best_score_m": 2.0,
             "mean_score_m": 1.0, "best_so_far_m": 2.0}
    cp = {"format": "tensegrity-evolve-checkpoint/1", "config": config, "generation": 1, "episodes": 8,
          "infeasible_episodes": 0, "rng_state": mt19937_64_state(1),
          "populations": [[member] * 4, [member] * 4], "curve": [stats],
          "best": {"rest_lengths_m": [[0.8, 0.9], [0.9, 1.0]], "score_m": 2.0, "feasible": True, "episode": 3,
                   "generation": 1}}
    out("evolve_checkpoint", "generation1.json", json.dumps(cp, indent=1).encode())
    out("evolve_checkpoint", "fresh.json",
        json.dumps(dict(cp, generation=0, episodes=0, curve=[], best=None)).encode())


def mpi_messages():
    """One message from another rank (sim/evolve/mpi_wire.hpp): tag byte (0 setup,
    1 hello, 2 job, 3 result), then the little-endian bytes."""
    def s(text):
        raw = text.encode()
        return struct.pack("<Q", len(raw)) + raw
    robot = (M.ROOT / "robots" / "superball.json").read_text()
    episode = s(robot) + s("0123456789abcdef") + struct.pack("<IdId", 24, 4.0, 5, 10.0)
    out("mpi_wire", "setup", b"\x00" + struct.pack("<I", 1) + s("tensegrity-episode/1") +
        struct.pack("<Q", len(episode)) + episode)
    out("mpi_wire", "hello", b"\x01" + struct.pack("<Ii", 1, 4) + s("rank1") + s("gcc-12 glibc x86_64") + s(""))
    team = struct.pack("<Q", 2) + b"".join(struct.pack("<Q", 2) + struct.pack("<dd", 0.8, 0.9) for _ in range(2))
    out("mpi_wire", "job", b"\x02" + struct.pack("<QQ", 1, 5) + team)
    out("mpi_wire", "result", b"\x03" + struct.pack("<QQdB", 1, 5, 2.5, 1) + s(""))
    out("mpi_wire", "result-error", b"\x03" + struct.pack("<QQdB", 1, 6, 0.0, 0) + s("episode threw"))



def write_all(make_corpus):
    global M
    M = make_corpus
    gate_runs()
    time_sync_runs()
    ground_runs()
    replay_csvs()
    store_records()
    endcap_stats()
    checkpoints()
    mpi_messages()
