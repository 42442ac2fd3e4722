#!/usr/bin/python3
# SPDX-License-Identifier: Apache-2.0
"""Rewrites the `--help` blocks of docs/reference/tensegrity.md from the built program,
so that the reference is what the program prints: under each "## SUBCOMMAND" heading,
the first ```text block is replaced. `--check` exits 1 naming the sections that differ.

  tools/reference_help.py [--tensegrity BIN] [--check]
"""
import argparse
import re
import sys

from tensegrity_tools import program

DOC = program.ROOT / "docs" / "reference" / "tensegrity.md"


def help_text(binary, words):
    out = program.text(binary, [*words, "--help"])
    # The program names itself by the path it was started with; the reference by its name.
    return re.sub(r"^Usage: \S*tensegrity", "Usage: tensegrity", out, flags=re.M).rstrip("\n")


def rewrite(text, binary):
    sections = re.split(r"(?m)^(## .+)$", text)
    changed = []
    for i in range(1, len(sections), 2):
        words = sections[i][3:].strip().split()
        body = sections[i + 1]
        m = re.search(r"```text\n(.*?)\n```", body, flags=re.S)
        if not m:
            continue
        new = help_text(binary, words)
        if new != m.group(1):
            changed.append(" ".join(words))
            sections[i + 1] = body[:m.start(1)] + new + body[m.end(1):]
    return "".join(sections), changed


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    program.add_option(ap)
    ap.add_argument("--check", action="store_true", help="only say which sections differ (exit 1 if any)")
    args = ap.parse_args()
    text, changed = rewrite(DOC.read_text(), program.find(args.tensegrity))
    if args.check:
        for c in changed:
            print(f"reference: `tensegrity {c} --help` differs from {DOC.name}", file=sys.stderr)
        return 1 if changed else 0
    DOC.write_text(text)
    print(f"reference: {len(changed)} section(s) rewritten: {', '.join(changed) or 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
