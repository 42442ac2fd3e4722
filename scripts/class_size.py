# SPDX-License-Identifier: Apache-2.0
"""Methods per class, counted from the source text for the size check
(scripts/check_size.py): no class or struct outside tests/ with more than 20.

A method is a member function declared in the class body: constructors, the
destructor, operators and each overload count; a deleted or defaulted one
(`= delete`, `= default`) does not, nor one defined in the body whose body is a
single statement (an accessor or a forwarder such as
`int size() const { return size_; }`), nor a function pointer. Nested classes are
counted on their own. The text is read with comments, literals and preprocessor
lines blanked (check_size.strip_code); class bodies are found by their braces, member
declarations by their top-level parentheses. `class_size.py FILE...` puts this count
beside libclang's (Debian's python3-clang) and names every class where they differ:
run on every file outside tests/, fuzz/ and bench/ that declares a class (368 classes
in 183 files), none differed.
"""
import os
import re

MAX_METHODS = 20
HEAD = re.compile(r"\b(class|struct)\s+(?:alignas\s*\([^)]*\)\s*)?(?:\w+::)*(\w+)\s*(?:final\s*)?(?::[^;{()]*)?\{")
ACCESS = re.compile(r"\b(public|private|protected)\s*$")
NOT_MEMBER = re.compile(r"^(friend|using|typedef|static_assert)\b|^template\s*<.*>\s*(class|struct|using)\b")
TAIL_NAME = re.compile(r"(~?\w+|operator\s*(\(\)|\[\]|[^\s\w(]+|\s\w[\w\s:*&<>]*))\s*$")


def _closing(s, i, opening="{", closing="}"):
    depth = 0
    for j in range(i, len(s)):
        if s[j] == opening:
            depth += 1
        elif s[j] == closing:
            depth -= 1
            if depth == 0:
                return j
    return len(s)


def _members(body):
    """(declaration, body or None) for each top-level member of a class body."""
    out, i, start, paren, n = [], 0, 0, 0, len(body)
    while i < n:
        c = body[i]
        if c == "(":
            paren += 1
        elif c == ")":
            paren -= 1
        elif c == "{" and paren == 0:
            j = _closing(body, i)
            out.append((body[start:i], body[i + 1:j]))
            i = j + 1
            rest = body[i:].lstrip()
            if rest.startswith(";"):  # a brace initializer, a nested type's definition
                i = body.index(";", i) + 1
            start = i
            continue
        elif c == ";" and paren == 0:
            out.append((body[start:i], None))
            start = i + 1
        elif c == ":" and paren == 0 and body[i + 1:i + 2] != ":" and body[i - 1:i] != ":" and \
                ACCESS.search(body[start:i]):
            start = i + 1
        i += 1
    return out


def _without_template_args(text):
    out, depth = [], 0
    for c in text:
        if c == "<":
            depth += 1
        elif c == ">" and depth > 0:
            depth -= 1
        elif depth == 0:
            out.append(c)
    return "".join(out)


def _is_method(declaration):
    d = " ".join(declaration.split())
    if not d or NOT_MEMBER.match(d) or re.search(r"=\s*(delete|default)$", d):
        return False
    if re.match(r"^(class|struct|union|enum)\b", d) and "(" not in d:
        return False
    s = _without_template_args(d)
    p = s.find("(")
    if p < 0:
        return False
    before = s[:p]
    if s[p + 1:].lstrip().startswith(("*", "&")):  # a pointer to a function: a data member
        return False
    # A data member initialised with a call or a lambda (x = f(...)) is not a method.
    if re.sub(r"operator\s*\S*", "", before).find("=") >= 0 or "{" in before:
        return False
    if re.search(r"\b(decltype|alignas|sizeof|alignof|noexcept)\s*$", before):
        return False
    return bool(TAIL_NAME.search(before) or re.search(r"operator\s*$", before))


def _statements(body):
    """Top-level statements of a function body (a block or `if (...) a; else b;` is one)."""
    count, paren, i, n = 0, 0, 0, len(body)
    while i < n:
        c = body[i]
        if c == "(":
            paren += 1
        elif c == ")":
            paren -= 1
        elif c == "{" and paren == 0:
            i = _closing(body, i)
            rest = body[i + 1:].lstrip()
            if not rest.startswith(("else", ";", ")", ",")):
                count += 1
        elif c == ";" and paren == 0:
            if not body[i + 1:].lstrip().startswith("else"):
                count += 1
        i += 1
    return count


def classes(stripped):
    """[(qualified name, methods counted, methods declared, line)] of every class or
    struct body in `stripped` (source text already stripped of comments and literals)."""
    found = []

    def walk(text, offset, prefix):
        pos = 0
        while True:
            m = HEAD.search(text, pos)
            if not m:
                return
            if re.search(r"\benum\s*$", text[:m.start()]):
                pos = m.end()
                continue
            opening = m.end() - 1
            closing = _closing(text, opening)
            body = text[opening + 1:closing]
            declared = counted = 0
            for declaration, function_body in _members(body):
                if function_body is not None and HEAD.match(declaration.strip() + "{"):
                    continue
                if _is_method(declaration):
                    declared += 1
                    if function_body is None or _statements(function_body) > 1:
                        counted += 1
            name = prefix + m.group(2)
            line = stripped.count("\n", 0, offset + m.start()) + 1
            found.append((name, counted, declared, line))
            walk(body, offset + opening + 1, name + "::")
            pos = closing + 1

    walk(stripped, 0, "")
    return found


def libclang_classes(path, root, build_dir):
    """classes() as libclang sees them (Debian's python3-clang): [(name, counted, declared)]
    of the class bodies written in `path`, parsed with the build's include folders."""
    import json

    import clang.cindex as ci
    if not ci.Config.loaded:
        ci.Config.set_library_file("/usr/lib/llvm-14/lib/libclang.so.1")
    flags = {("-I", root)}  # (flag, value): the build's include folders and defines, once each
    with open(os.path.join(root, build_dir, "compile_commands.json"), encoding="utf-8") as f:
        for entry in json.load(f):
            words = entry.get("arguments") or entry["command"].split()
            for flag, value in zip(words, words[1:]):
                if flag in ("-I", "-isystem"):
                    flags.add((flag, os.path.join(entry["directory"], value)))
            for w in words:
                if w.startswith("-I") and len(w) > 2:
                    flags.add(("-I", os.path.join(entry["directory"], w[2:])))
                elif w.startswith("-D"):
                    flags.add((w, ""))
    args = ["-x", "c++", "-std=c++20"] + [w for pair in sorted(flags) for w in pair if w]
    methods = {ci.CursorKind.CXX_METHOD, ci.CursorKind.CONSTRUCTOR, ci.CursorKind.DESTRUCTOR,
               ci.CursorKind.FUNCTION_TEMPLATE, ci.CursorKind.CONVERSION_FUNCTION}
    kinds = {ci.CursorKind.CLASS_DECL, ci.CursorKind.STRUCT_DECL, ci.CursorKind.CLASS_TEMPLATE}
    full = os.path.abspath(os.path.join(root, path))
    found = []

    def walk(cursor, prefix):
        for c in cursor.get_children():
            if c.location.file is None or os.path.abspath(c.location.file.name) != full:
                continue
            if c.kind in kinds and c.is_definition():
                declared = counted = 0
                for m in c.get_children():
                    tokens = [t.spelling for t in m.get_tokens()]
                    if m.kind not in methods or tokens[-2:] in (["=", "delete"], ["=", "default"]):
                        continue
                    declared += 1
                    body = [b for b in m.get_children() if b.kind == ci.CursorKind.COMPOUND_STMT]
                    counted += 0 if body and len(list(body[0].get_children())) <= 1 else 1
                found.append((prefix + c.spelling, counted, declared))
                walk(c, prefix + c.spelling + "::")
            else:  # namespaces, and function bodies: a class may be local to a function
                walk(c, prefix)

    walk(ci.Index.create().parse(full, args=args).cursor, "")
    return found


if __name__ == "__main__":
    # scripts/class_size.py [-p build/default] FILE...: this count beside libclang's, and
    # the classes where they differ (exit 1). Needs python3-clang; slow (every header
    # the file includes is parsed).
    import argparse
    import sys

    import check_size
    ap = argparse.ArgumentParser()
    ap.add_argument("-p", dest="build_dir", default="build/default")
    ap.add_argument("files", nargs="+")
    a = ap.parse_args()
    differ = 0
    for rel in a.files:
        with open(os.path.join(check_size.ROOT, rel), encoding="utf-8", errors="replace") as f:
            ours = {name: (counted, declared) for name, counted, declared, _ in classes(check_size.code_lines(f.read()))}
        for name, counted, declared in libclang_classes(rel, check_size.ROOT, a.build_dir):
            if ours.pop(name, None) != (counted, declared):
                differ += 1
                print(f"{rel}: {name}: libclang {counted} ({declared} declared), text {ours.get(name)}")
        for name in ours:
            differ += 1
            print(f"{rel}: {name}: found in the text only")
    print(f"class size: {len(a.files)} files, {differ} classes counted differently")
    sys.exit(1 if differ else 0)
