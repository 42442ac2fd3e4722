# SPDX-License-Identifier: Apache-2.0
"""Methods per class, counted from the source text for the size check
(scripts/check_size.py): no class or struct outside tests/ with more than 20.

A method is a member function declared in the class body: constructors, the
destructor, operators and each overload count; a deleted one (`= delete`) does not,
nor one defined in the body whose body is a single statement (an accessor or a
forwarder such as `int size() const { return size_; }`). Nested classes are counted
on their own. The text is read with comments, literals and preprocessor lines
blanked (check_size.strip_code); class bodies are found by their braces, member
declarations by their top-level parentheses. Checked against libclang's view of the
tree (every class of firmware/, sim/, hil/, ground/, cli/, view/, format/, msgs/):
the same count for each.
"""
import re

MAX_METHODS = 20
HEAD = re.compile(r"\b(class|struct)\s+(?:alignas\s*\([^)]*\)\s*)?(\w+)\s*(?:final\s*)?(?::[^;{()]*)?\{")
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
    if not d or NOT_MEMBER.match(d) or re.search(r"=\s*delete$", d):
        return False
    if re.match(r"^(class|struct|union|enum)\b", d) and "(" not in d:
        return False
    s = _without_template_args(d)
    p = s.find("(")
    if p < 0:
        return False
    before = s[:p]
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
