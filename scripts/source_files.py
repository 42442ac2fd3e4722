#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The project's files, for the checks (format, layers, size): what git tracks when the
tree is a git checkout and git is installed; otherwise (a release tarball, a copy, a
machine without git) the files on disk, less what .gitignore ignores, with a note on
stderr saying so. Both give the same list for a clean checkout
(tests/scripts/checks_without_git_test.sh holds them to it).

  scripts/source_files.py [--root DIR] [GLOB ...]     one path per line, relative to DIR
"""
import argparse
import fnmatch
import os
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _from_git(root):
    out = subprocess.run(["git", "ls-files", "-z"], cwd=root, capture_output=True, text=True, check=True).stdout
    return [f for f in out.split("\0") if f and os.path.isfile(os.path.join(root, f))]


def _from_disk(root):
    # Debian's python3-pathspec: .gitignore's own rules (negation, '**', anchoring), so
    # the list is git's without git.
    import pathspec
    path = os.path.join(root, ".gitignore")
    lines = open(path, encoding="utf-8").read().splitlines() if os.path.exists(path) else []
    spec = pathspec.GitIgnoreSpec.from_lines(lines)
    found = []
    for folder, dirs, names in os.walk(root):
        rel_folder = os.path.relpath(folder, root)
        rel_folder = "" if rel_folder == "." else rel_folder
        dirs[:] = sorted(d for d in dirs if d != ".git" and not spec.match_file(os.path.join(rel_folder, d) + "/"))
        for n in sorted(names):
            rel = os.path.join(rel_folder, n)
            if not spec.match_file(rel):
                found.append(rel)
    return found


def files(root=ROOT, globs=None, quiet=False):
    """Paths relative to `root`, sorted; with `globs`, those any glob matches
    (fnmatch: '*' spans folders, as in git's pathspecs)."""
    have_git = os.path.exists(os.path.join(root, ".git")) and shutil.which("git") is not None
    if have_git:
        listed = _from_git(root)
    else:
        if not quiet:
            why = "git is not installed" if os.path.exists(os.path.join(root, ".git")) else "no .git here"
            print(f"source_files: {why}: checking the files on disk, less what .gitignore ignores", file=sys.stderr)
        listed = _from_disk(root)
    if globs:
        listed = [f for f in listed if any(fnmatch.fnmatchcase(f, g) for g in globs)]
    return sorted(listed)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--root", default=ROOT, help="the tree (default: this checkout)")
    ap.add_argument("globs", nargs="*", help="only paths matching one of these, e.g. '*.cpp'")
    args = ap.parse_args()
    for f in files(os.path.abspath(args.root), args.globs):
        print(f)
    return 0


if __name__ == "__main__":
    sys.exit(main())
