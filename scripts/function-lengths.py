#!/usr/bin/env python3
"""Lines of every C function definition in the given folders (.c and .inc files), longest first.

A definition starts at a line that opens a brace at file scope after a closing parenthesis (the
signature may span lines) and ends where the brace depth returns to zero; strings, character
literals and comments are blanked first so their braces do not count. Initialisers
(`= {`), struct/enum/union bodies and `extern "C"` blocks are not functions. A function's length
counts its signature's first line through its closing brace.

usage: function-lengths.py [--max N] [--all] DIR...
       function-lengths.py --self-test   (the counter against snippets of known length)
  prints "LINES FILE:LINE NAME" for each function longer than N (default 120), longest first;
  exit status 1 when there is one (the CONTRIBUTING.md rule: no function over 120 lines).
  --all prints every function."""
import os
import signal
import re
import sys


def blank(text):
    """The source with comments, strings and character literals replaced by spaces (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(c + " " * (j - i - 2) + c if j - i >= 2 else c)
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def signature_name(head):
    """The name before the parameter list that `head` (text before a brace) ends with, or None."""
    if not head.endswith(")"):
        return None
    depth, j = 0, len(head) - 1
    while j >= 0:
        depth += {")": 1, "(": -1}.get(head[j], 0)
        if depth == 0:
            break
        j -= 1
    if j < 0 or ";" in head[j:] or "#" in head[j:]:
        return None
    m = re.search(r"([A-Za-z_]\w*)\)?\s*$", head[:j])  # SFX(name)(...) names name
    return m.group(1) if m else None


def functions(path):
    """(name, first line, lines) of each function defined in the file."""
    lines = blank(open(path, errors="replace").read()).split("\n")
    found = []
    depth = 0
    start = None
    name = None
    for i, line in enumerate(lines):
        if depth == 0 and "{" in line:
            first = max(0, i - 8)
            head = "\n".join(lines[first:i + 1])
            head = head[:head.rfind("{")].rstrip()
            head = re.sub(r"__attribute__\s*\(\(.*?\)\)\s*$", "", head).rstrip()
            name = signature_name(head)
            init = re.search(r"=\s*$", head) or re.match(r"\s*(struct|enum|union|typedef)\b", line)
            if name and not init and name not in ("if", "for", "while", "switch", "sizeof"):
                # the signature's first line: the line holding the name
                start = first + head[:head.rfind(name)].count("\n")
        depth += line.count("{") - line.count("}")
        if depth == 0 and start is not None:
            found.append((name, start + 1, i - start + 1))
            start = None
    return found


def self_test():
    """The counter on snippets whose lengths are known: braces in strings, characters and comments,
    a multi-line signature, an initialiser and a struct are not functions or do not count."""
    import tempfile
    body = lambda n: "".join("    x += %d; /* } */ s = \"{\"; c = '}';\n" % k for k in range(n))
    src = ("struct s {\n    int a;\n};\nstatic const int t[2] = {\n    1, 2};\n"
           "static int f120(int a,\n                int b)\n{\n" + body(116) + "}\n"
           "int f121(void)\n{\n" + body(118) + "}\n"
           "#define SFX(n) n##_f\nstatic float SFX(g)(const float (*J)[3]) {\n    return J[0][0];\n}\n")
    with tempfile.NamedTemporaryFile("w", suffix=".c", delete=False) as f:
        f.write(src)
    try:
        got = {name: n for name, _, n in functions(f.name)}
    finally:
        os.unlink(f.name)
    want = {"f120": 120, "f121": 121, "g": 3}
    if got != want:
        print("FAIL: counted %s, want %s" % (got, want), file=sys.stderr)
        return 1
    print("self-test: %s" % got)
    return 0


def main(argv):
    if argv == ["--self-test"]:
        return self_test()
    limit, show_all, dirs = 120, False, []
    args = iter(argv)
    for a in args:
        if a == "--max":
            limit = int(next(args))
        elif a == "--all":
            show_all = True
        else:
            dirs.append(a)
    if not dirs:
        print(__doc__, file=sys.stderr)
        return 2
    rows = []
    for d in dirs:
        paths = [d] if os.path.isfile(d) else [os.path.join(dp, f) for dp, _, fs in os.walk(d) for f in fs]
        for p in sorted(paths):
            if p.endswith((".c", ".inc")):
                rows += [(n, p, line, name) for name, line, n in functions(p)]
    rows.sort(key=lambda r: (-r[0], r[1], r[2]))
    over = [r for r in rows if r[0] > limit]
    for n, p, line, name in rows if show_all else over:
        print("%d %s:%d %s" % (n, p, line, name))
    if over and not show_all:
        print("%d function(s) over %d lines" % (len(over), limit), file=sys.stderr)
    return 1 if over else 0


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)
    sys.exit(main(sys.argv[1:]))
