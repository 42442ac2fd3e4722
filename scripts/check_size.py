#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The size rule of the project's guide, enforced: outside tests/, no source file (C++
or Python) over 400 lines, no function over 80 lines and no C++ class over 20 methods,
except those listed with a reason in scripts/size-exceptions.txt (and
docs/design/architecture.md, "Size exceptions").

Classes: methods counted from the source text (scripts/class_size.py says what counts).

Files: a plain line count. Python functions (and methods, nested ones each on their
own): Python's own parser (`ast`), from the `def` line to the function's last line.
C++ functions: clang-tidy's readability-function-size with
LineThreshold 80, over the build's compile_commands.json. clang-tidy parses every
header a file includes (Eigen, Fast DDS: 5-10 s of CPU per file), so it runs only on
the files that can hold a function over 80 lines: those with a brace block longer
than that which is not a namespace, class, struct, union, enum or extern block. That
pre-filter errs one way only (a class body written like a function sends its file to
clang-tidy for nothing; a function body is never taken for a class), and --all runs
clang-tidy on every file to show it.

  scripts/check_size.py [-p build/default] [--all] [--self-test] [-j N]
"""
import argparse
import ast
import concurrent.futures
import os
import re
import subprocess
import sys
import tempfile

import class_size
import source_files

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MAX_FILE_LINES = 400
MAX_FUNCTION_LINES = 80
SOURCE = re.compile(r"\.(cpp|cc|c|hpp|h)$")
PYTHON = re.compile(r"\.py$")
TYPE_BLOCK = re.compile(r"^\s*(template\s*<.*>\s*)?(namespace|class|struct|union|enum|extern)\b")
TIDY_CONFIG = "{CheckOptions: [{key: readability-function-size.LineThreshold, value: %d}]}" % MAX_FUNCTION_LINES
WARNING = re.compile(r"^(.*?):(\d+):\d+: warning: function '([^']*)' exceeds recommended size")


def sources():
    return [f for f in source_files.files(ROOT) if SOURCE.search(f) and not f.startswith("tests/")]


def python_sources():
    return [f for f in source_files.files(ROOT) if PYTHON.search(f) and not f.startswith("tests/")]


def python_functions(path):
    """(line, qualified name, lines) of every function and method in a Python file;
    a nested function is named outer.inner and counted inside its outer one too."""
    with open(os.path.join(ROOT, path), encoding="utf-8") as f:
        tree = ast.parse(f.read(), filename=path)
    found = []

    def walk(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                name = prefix + child.name
                if not isinstance(child, ast.ClassDef):
                    found.append((child.lineno, name, child.end_lineno - child.lineno + 1))
                walk(child, name + ".")
            else:
                walk(child, prefix)

    walk(tree, "")
    return found


def python_problems(files, function_ok, used):
    """The Python functions over the limit that are not listed (listed ones go to `used`)."""
    problems = []
    for path in files:
        try:
            functions = python_functions(path)
        except SyntaxError as e:
            problems.append(f"{path}:{e.lineno}: not Python the checker can parse ({e.msg})")
            continue
        for line, name, length in functions:
            if length <= MAX_FUNCTION_LINES:
                continue
            key = next((k for k in ((path, name), (path, name.split(".")[-1])) if k in function_ok), None)
            if key:
                used.add(("function",) + key)
            else:
                problems.append(f"{path}:{line}: function '{name}' is {length} lines (at most {MAX_FUNCTION_LINES})")
    return problems


def read_exceptions(path):
    files, functions, classes = {}, {}, {}
    with open(path, encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            head, sep, reason = line.partition(" -- ")
            words = head.split()
            if not sep or not reason.strip() or not words or words[0] not in ("file", "function", "class") or \
                    len(words) != (2 if words[0] == "file" else 3):
                sys.exit(f"{path}:{n}: expected 'file PATH -- REASON', 'function PATH NAME -- REASON' "
                         "or 'class PATH NAME -- REASON'")
            if words[0] == "file":
                files[words[1]] = reason
            elif words[0] == "function":
                functions[(words[1], words[2])] = reason
            else:
                classes[(words[1], words[2])] = reason
    return files, functions, classes


def strip_code(text):
    """The text with comments, string and character literals blanked, lines kept."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append("\n" * text.count("\n", i, j))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            k = text.find("(", i)
            delim = ")" + text[i + 2:k] + '"'
            j = text.find(delim, k)
            j = n if j < 0 else j + len(delim)
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum():
                out.append(" ")  # a digit separator (1'000)
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def code_lines(text):
    """strip_code's text with preprocessor lines blanked too."""
    return "\n".join("" if line.lstrip().startswith("#") else line for line in strip_code(text).split("\n"))


def big_classes(path):
    """[(line, class name, methods)] of the classes in `path` over class_size.MAX_METHODS."""
    with open(os.path.join(ROOT, path), encoding="utf-8", errors="replace") as f:
        text = code_lines(f.read())
    return [(line, name, counted) for name, counted, _, line in class_size.classes(text)
            if counted > class_size.MAX_METHODS]


def longest_code_block(path):
    """Lines of the longest brace block that is not a namespace/type block."""
    with open(os.path.join(ROOT, path), encoding="utf-8", errors="replace") as f:
        lines = strip_code(f.read()).split("\n")
    stack, longest, previous = [], 0, ""
    for number, line in enumerate(lines):
        for c in line:
            if c == "{":
                opener = line if line.strip() != "{" else previous
                stack.append((number, bool(TYPE_BLOCK.match(opener))))
            elif c == "}" and stack:
                start, is_type = stack.pop()
                if not is_type:
                    longest = max(longest, number - start + 1)
        if line.strip():
            previous = line
    return longest


def tidy(path, build_dir):
    cmd = ["clang-tidy", "-p", build_dir, "--quiet", "--checks=-*,readability-function-size", "--config=" + TIDY_CONFIG,
           "--extra-arg=-Wno-error", "--extra-arg=-Wno-unknown-warning-option", path]
    r = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    found = []
    for line in r.stdout.splitlines():
        m = WARNING.match(line)
        if m:
            found.append((os.path.relpath(os.path.join(ROOT, m.group(1)), ROOT), int(m.group(2)), m.group(3)))
    return found


def python_self_test():
    """The Python count flags a planted 81-line function (a nested one and a method too)
    and not an 80-line one."""
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "planted.py"), "w", encoding="utf-8") as f:
            for name, n in (("long_one", MAX_FUNCTION_LINES + 1), ("short_one", MAX_FUNCTION_LINES)):
                f.write("def %s(x):\n%s    return x\n\n\n" % (name, "    x += 1\n" * (n - 2)))
            f.write("class Planted:\n    def method(self):\n        def inner():\n%s            return 1\n"
                    "        return inner\n" % ("            pass\n" * (MAX_FUNCTION_LINES - 1)))
        global ROOT
        saved, ROOT = ROOT, d
        try:
            flagged = python_problems(["planted.py"], {}, set())
        finally:
            ROOT = saved
    names = [re.search(r"function '([^']*)'", p).group(1) for p in flagged]
    if names != ["long_one", "Planted.method", "Planted.method.inner"]:
        sys.exit(f"size check self-test: the Python count flagged {names}, "
                 f"expected ['long_one', 'Planted.method', 'Planted.method.inner']")
    print("size check self-test: a Python function of 81 lines is flagged (also a method and a nested one), "
          "one of 80 is not")


def self_test(jobs):
    """clang-tidy and the pre-filter flag a planted 81-line function and not an 80-line one
    (clang-tidy's count: from the line of the opening brace to that of the closing one)."""
    python_self_test()
    with tempfile.TemporaryDirectory() as d:
        path = os.path.join(d, "planted.cpp")
        with open(path, "w", encoding="utf-8") as f:
            for name, n in (("long_one", MAX_FUNCTION_LINES + 1), ("short_one", MAX_FUNCTION_LINES)):
                f.write("int %s(int x) {\n%s  return x;\n}\n" % (name, "  x += 1;\n" * (n - 2)))
        cmd = ["clang-tidy", "--quiet", "--checks=-*,readability-function-size", "--config=" + TIDY_CONFIG, path, "--",
               "-std=c++20"]
        out = subprocess.run(cmd, capture_output=True, text=True).stdout
        names = [m.group(3) for m in map(WARNING.match, out.splitlines()) if m]
        if names != ["long_one"]:
            sys.exit(f"size check self-test: clang-tidy flagged {names}, expected ['long_one']")
        global ROOT
        saved, ROOT = ROOT, d
        try:
            if longest_code_block("planted.cpp") <= MAX_FUNCTION_LINES:
                sys.exit("size check self-test: the pre-filter missed the planted function")
        finally:
            ROOT = saved
    print("size check self-test: an 81-line function is flagged, an 80-line one is not")
    self_test_classes()


def self_test_classes():
    """A planted class with 21 methods is flagged, one with 20 (and accessors, deleted and
    defaulted members, a function pointer, data members built by calls, a nested class)
    is not."""
    def planted(name, methods):
        lines = ["class %s final : public Base {" % name, " public:", "  %s(const %s&) = delete;" % (name, name),
                 "  ~%s() override = default;" % name, "  void (*on_done)(int) = nullptr;",
                 "  int size() const { return size_; }", "  void set(int v) noexcept override { size_ = v; }",
                 "  std::function<void(int)> callback = [](int) {};", "  std::array<int, 3> a{1, 2, 3};",
                 "  struct Inner {", "    void inner_one();", "    void inner_two() { x = 1; y = 2; }", "  };"]
        lines += ["  void m%d(int x);" % i for i in range(methods - 2)]
        lines += ["  bool operator==(const %s&) const;" % name,
                  "  void twice() {", "    size_ = 1;", "    size_ = 2;", "  }", " private:", "  int size_ = 0;", "};"]
        return "\n".join(lines) + "\n"
    text = code_lines(planted("Over", class_size.MAX_METHODS + 1) + planted("Within", class_size.MAX_METHODS))
    counts = {name: counted for name, counted, _, _ in class_size.classes(text)}
    expected = {"Over": class_size.MAX_METHODS + 1, "Over::Inner": 2, "Within": class_size.MAX_METHODS,
                "Within::Inner": 2}
    if counts != expected:
        sys.exit(f"size check self-test: class methods counted {counts}, expected {expected}")
    print(f"size check self-test: a class of {class_size.MAX_METHODS + 1} methods is flagged, "
          f"one of {class_size.MAX_METHODS} is not")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-p", dest="build_dir", default="build/default", help="build folder with compile_commands.json")
    ap.add_argument("--all", action="store_true", help="clang-tidy on every file, not only the pre-filter's")
    ap.add_argument("--self-test", action="store_true", help="first check the check on a planted function and class")
    ap.add_argument("-j", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--exceptions", default=os.path.join(ROOT, "scripts", "size-exceptions.txt"))
    args = ap.parse_args()
    if args.self_test:
        self_test(args.j)
    file_ok, function_ok, class_ok = read_exceptions(args.exceptions)
    problems, used = [], set()
    files = sources()
    python = python_sources()
    for path in files + python:
        with open(os.path.join(ROOT, path), encoding="utf-8", errors="replace") as f:
            count = sum(1 for _ in f)
        if count > MAX_FILE_LINES:
            if path in file_ok:
                used.add(("file", path))
            else:
                problems.append(f"{path}: {count} lines (at most {MAX_FILE_LINES})")
        for line, name, methods in big_classes(path):
            if (path, name) in class_ok:
                used.add(("class", path, name))
            else:
                problems.append(f"{path}:{line}: class '{name}' has {methods} methods (at most {class_size.MAX_METHODS})")
    db = os.path.join(ROOT, args.build_dir, "compile_commands.json")
    if not os.path.exists(db):
        sys.exit(f"size check: no {db} (configure the build first)")
    candidates = files if args.all else [f for f in files if longest_code_block(f) > MAX_FUNCTION_LINES]
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.j)) as pool:
        results = list(pool.map(lambda f: tidy(f, args.build_dir), candidates))
    seen = set()
    for path, line, name in sorted({w for r in results for w in r}):
        if path.startswith("tests/") or not any(path == f for f in files) or (path, name) in seen:
            continue
        seen.add((path, name))
        short = name.split("::")[-1]
        key = next((k for k in ((path, name), (path, short)) if k in function_ok), None)
        if key:
            used.add(("function",) + key)
        else:
            problems.append(f"{path}:{line}: function '{name}' over {MAX_FUNCTION_LINES} lines")
    problems += python_problems(python, function_ok, used)
    stale = [f"file {p}" for p in file_ok if ("file", p) not in used] + \
            [f"function {p} {n}" for (p, n) in function_ok if ("function", p, n) not in used] + \
            [f"class {p} {n}" for (p, n) in class_ok if ("class", p, n) not in used]
    print(f"size check: {len(files)} C++ and {len(python)} Python files counted, {len(candidates)} through clang-tidy, "
          f"{len(used)} listed exceptions in use")
    for s in stale:  # a warning: the branch that fixed it may land before the list is edited
        print(f"size check: warning: {args.exceptions}: '{s}' is within the limits now: remove it", file=sys.stderr)
    for p in problems:
        print("size check: " + p, file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
