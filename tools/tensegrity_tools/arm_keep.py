# SPDX-License-Identifier: Apache-2.0
"""An arm's runs, kept in the repository so another machine can carry them on.

A 5000-episode arm takes hours on two cores, more than one sitting; each seed's
checkpoint (tensegrity evolve --checkpoint) lets a later run continue it exactly,
even with a larger --episodes. pack() copies what an arm's summary and a resume
need (curve, policy, summary, the last checkpoint compressed with xz, about a fifth
of its size) and leaves the checkpoint's previous copy and the logs behind;
unpack_checkpoint() restores the checkpoint beside it before a seed resumes.
"""
import lzma
import pathlib
import shutil

KEPT = ("summary.json", "curve.csv", "policy.json", "command.txt")


def unpack_checkpoint(run):
    """Restores ckpt/checkpoint.json from its .xz if only the packed copy is there."""
    ckpt = pathlib.Path(run) / "ckpt"
    packed, plain = ckpt / "checkpoint.json.xz", ckpt / "checkpoint.json"
    if packed.exists() and not plain.exists():
        try:
            text = lzma.decompress(packed.read_bytes())
        except lzma.LZMAError as e:  # the packed copy stays as it was, for another try
            raise ValueError(f"{packed}: not a readable xz checkpoint ({e})") from None
        plain.write_bytes(text)
        return True
    return False


def pack(arm, dest):
    """Copies arm's robot.json, arm.csv and runs/sK/ to dest; returns the seeds copied."""
    arm, dest = pathlib.Path(arm), pathlib.Path(dest)
    if arm.resolve() == dest.resolve():
        raise ValueError(f"--pack {dest}: that is the arm itself")
    dest.mkdir(parents=True, exist_ok=True)
    for name in ("robot.json", "arm.csv"):
        if (arm / name).exists():
            shutil.copy2(arm / name, dest / name)
    seeds = []
    for run in sorted((arm / "runs").glob("s*"), key=lambda p: int(p.name[1:]) if p.name[1:].isdigit() else -1):
        out = dest / "runs" / run.name
        out.mkdir(parents=True, exist_ok=True)
        for name in KEPT:
            if (run / name).exists():
                shutil.copy2(run / name, out / name)
        checkpoint = run / "ckpt" / "checkpoint.json"
        if checkpoint.exists():
            (out / "ckpt").mkdir(exist_ok=True)
            (out / "ckpt" / "checkpoint.json.xz").write_bytes(lzma.compress(checkpoint.read_bytes(), preset=9))
        seeds.append(run.name)
    return seeds
