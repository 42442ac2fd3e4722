#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The architecture's rules, enforced: which room may include which, read from the
declarative table scripts/layers.json (README "What is here", docs/design/architecture.md).

A room is one folder of the tree, and every tracked C++ file belongs to the room
whose folder is the longest prefix of its path (a file in no room's folder is a
violation too). Each #include "..." of another room's file must name a room in its
own room's may_include (the rooms its CMake target links), and must not reach a
room whose folder holds the includer's own (an include that runs back up a floor:
the rooms a room stands on sit beside it, never above it). Each #include <...> must
obey the room's system rule ("std": the C++ standard library only, as core/ must;
"forbid": prefixes such as fastdds/ that the room must not touch). A violation
names the file, the line, the include and the rule.

Every target has the source root as its include directory (cmake/Rooms.cmake), so
the compiler would find any header: this check is what keeps the rooms apart.

  scripts/check_layers.py [--self-test]
"""
import argparse
import json
import os
import re
import sys
import tempfile

import source_files

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE = re.compile(r"\.(cpp|cc|hpp|h|inc)$")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')
# The C++20 standard library's headers, and the C library's <cxxx> forms.
STD_HEADERS = set("""
algorithm any array atomic barrier bit bitset cassert cctype cerrno cfenv cfloat charconv chrono cinttypes
climits clocale cmath codecvt compare complex concepts condition_variable coroutine csetjmp csignal cstdarg
cstddef cstdint cstdio cstdlib cstring ctime cuchar cwchar cwctype deque exception execution expected filesystem
format forward_list fstream functional future initializer_list iomanip ios iosfwd iostream istream iterator
latch limits list locale map memory memory_resource mutex new numbers numeric optional ostream queue random
ranges ratio regex scoped_allocator semaphore set shared_mutex source_location span sstream stack stdexcept
stop_token streambuf string string_view syncstream system_error thread tuple type_traits typeindex typeinfo
unordered_map unordered_set utility valarray variant vector version
""".split())


def load_rules(path):
    with open(path, encoding="utf-8") as f:
        doc = json.load(f)
    if doc.get("format") != "tensegrity-layers/2":
        sys.exit(f"{path}: format: expected tensegrity-layers/2")
    rooms = {}
    folders = {}
    for i, r in enumerate(doc["rooms"]):
        for key in ("name", "folder", "may_include"):
            if key not in r:
                sys.exit(f"{path}: rooms[{i}]: missing '{key}'")
        folder = r["folder"]
        if not isinstance(folder, str) or not folder.endswith("/") or folder.startswith("/") or ".." in folder:
            sys.exit(f"{path}: rooms[{i}].folder: expected a folder of the tree ending in '/', got {folder!r}")
        if folder in folders:
            sys.exit(f"{path}: rooms[{i}].folder: {folder} is already room '{folders[folder]}'")
        folders[folder] = r["name"]
        rooms[r["name"]] = r
    for r in rooms.values():
        for other in r["may_include"]:
            if other != "*" and other not in rooms:
                sys.exit(f"{path}: room {r['name']}: may_include names unknown room '{other}'")
    return rooms


def room_of(path, rooms):
    best, best_len = None, -1
    for r in rooms.values():
        if path.startswith(r["folder"]) and len(r["folder"]) > best_len:
            best, best_len = r, len(r["folder"])
    return best


def check_file(root, rel, rooms, tracked):
    own = room_of(rel, rooms)
    if own is None:
        # Every C++ file sits in a room's folder: a file outside them is unchecked.
        return [f"{rel}: in no room's folder (scripts/layers.json)"]
    problems = []
    with open(os.path.join(root, rel), encoding="utf-8", errors="replace") as f:
        for n, line in enumerate(f, 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            kind, name = m.groups()
            where = f"{rel}:{n}: #include {kind}{name}{'>' if kind == '<' else kind}"
            if kind == '"' and name in tracked:
                other = room_of(name, rooms)
                if other is None or other is own:
                    continue
                if own["folder"].startswith(other["folder"]):
                    problems.append(f"{where}: room '{own['name']}' ({own['folder']}) runs back up a floor to room "
                                    f"'{other['name']}' ({other['folder']}), whose folder holds its own")
                elif "*" in own["may_include"]:
                    continue
                elif other["name"] not in own["may_include"]:
                    problems.append(f"{where}: room '{own['name']}' may not include room '{other['name']}' "
                                    f"(may include: {', '.join(own['may_include']) or 'no other room'})")
            elif kind == "<":
                if own.get("system") == "std" and name not in STD_HEADERS:
                    problems.append(f"{where}: room '{own['name']}' may include the C++ standard library only")
                for prefix in own.get("forbid", []):
                    if name.startswith(prefix):
                        problems.append(f"{where}: room '{own['name']}' may not include <{prefix}...>")
    return problems


def check_tree(root, rules_path, files):
    rooms = load_rules(rules_path)
    tracked = set(files)
    problems = []
    for rel in sorted(files):
        if SOURCE.search(rel):
            problems += check_file(root, rel, rooms, tracked)
    return problems


def tracked_files(root):
    return source_files.files(root)


def self_test():
    """The checker must catch each kind of violation, and pass a clean tree."""
    rules = {"format": "tensegrity-layers/2", "rooms": [
        {"name": "core", "folder": "core/", "may_include": [], "system": "std"},
        {"name": "app", "folder": "app/", "may_include": ["core"], "forbid": ["fastdds/"]},
        {"name": "prog", "folder": "app/prog/", "may_include": ["core", "app", "net"]},
        {"name": "net", "folder": "net/", "may_include": ["core"]}]}
    files = {
        "core/a.hpp": "#include <cstdint>\n#include <vector>\n",
        "core/bad.hpp": "#include <unistd.h>\n#include \"app/x.hpp\"\n",
        "app/x.hpp": "#include \"core/a.hpp\"\n#include <fastdds/dds/x.hpp>\n",
        "app/y.cpp": "#include \"net/n.hpp\"\n#include \"app/x.hpp\"\n",
        "app/prog/main.cpp": "#include \"net/n.hpp\"\n#include \"core/a.hpp\"\n#include \"app/x.hpp\"\n",
        "net/n.hpp": "#include \"core/a.hpp\"\n#include \"unknown/not_tracked.hpp\"\n",
        "stray/s.cpp": "#include \"core/a.hpp\"\n",
    }
    with tempfile.TemporaryDirectory() as d:
        for rel, text in files.items():
            os.makedirs(os.path.dirname(os.path.join(d, rel)), exist_ok=True)
            with open(os.path.join(d, rel), "w", encoding="utf-8") as f:
                f.write(text)
        rules_path = os.path.join(d, "layers.json")
        with open(rules_path, "w", encoding="utf-8") as f:
            json.dump(rules, f)
        got = check_tree(d, rules_path, list(files))
    expect = ["core/bad.hpp:1: #include <unistd.h>", "core/bad.hpp:2: #include \"app/x.hpp\"",
              "app/x.hpp:2: #include <fastdds/dds/x.hpp>", "app/y.cpp:1: #include \"net/n.hpp\"",
              "app/prog/main.cpp:3: #include \"app/x.hpp\"", "stray/s.cpp: in no room's folder"]
    ok = len(got) == len(expect) and all(any(p.startswith(e) for p in got) for e in expect)
    if not ok:
        print("check_layers self-test FAILED; expected violations:\n  " + "\n  ".join(expect) +
              "\ngot:\n  " + "\n  ".join(got))
        return False
    return True


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--rules", default=os.path.join(ROOT, "scripts", "layers.json"))
    p.add_argument("--self-test", action="store_true", help="first check that the checker catches violations")
    args = p.parse_args()
    if args.self_test and not self_test():
        return 1
    tracked = tracked_files(ROOT)
    problems = check_tree(ROOT, args.rules, tracked)
    for line in problems:
        print(line)
    files = sum(1 for f in tracked if SOURCE.search(f))
    if problems:
        print(f"layers: {len(problems)} violation(s) of scripts/layers.json")
        return 1
    print(f"layers: {files} files follow scripts/layers.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
