#!/usr/bin/env python3
"""include-graph.py [--check] [SOURCE_ROOT] — which folder's sources include which other folder's
headers: each quoted #include resolved against the including file's folder, then the build's
include directories (meson.build); generated headers (embedded shaders, the GL table) and system
headers are left out, and so is <volfx/volfx.h>, which every folder may include.
docs/architecture.md ("What each folder may include") is this graph with its rules: run it
after moving code.

Inside each folder it also finds circles between modules (a module is x.c with x.h): module A
uses B when a function A defines (or a static inline one in A's header) calls a function B
defines, non-static or inline in B's header. A circle (scene.c calls scene_beams.c, which calls
back into scene.c) means the files are one module in pieces; the layers are a tree only when
there is none. (The folders' graph is not a tree: plugin/ holds the context and the effect
registry, which its gpu/ and effect folders include and which includes their headers.) --check
prints only the module circles and exits 1 when there is one (test unit/include_graph)."""
import os, re, sys, collections
args = [a for a in sys.argv[1:] if a != "--check"]
check = "--check" in sys.argv[1:]
root = args[0] if args else "."
incdirs = ["plugin/include", "plugin/lab", "plugin", "runtime", "shaders", "tetra", "reference", "sample_game", "tests/common", "bench"]
def folder(p):
    parts = p.split("/")
    if parts[0] in ("plugin", "runtime", "tests", "shaders") and len(parts) > 2:
        return "/".join(parts[:2])
    return parts[0]
edges = collections.defaultdict(set)
byfolder = collections.defaultdict(dict)  # folder -> {path: text}, for the module circles
for d, dirs, fs in os.walk(root):
    dirs.sort()
    rel = os.path.relpath(d, root)
    if rel.startswith(("build", ".git", "subprojects")) or "/build" in rel:
        continue
    for f in fs:
        if not f.endswith((".c", ".h", ".cpp", ".inc")):
            continue
        src = os.path.normpath(os.path.join(rel, f))
        text = open(os.path.join(root, src), errors="replace").read()
        if f.endswith((".c", ".h")):
            byfolder[rel][src] = text
        for m in re.finditer(r'^\s*#\s*include\s+(["<])([^">]+)[">]', text, re.M):
            quoted, inc = m.group(1) == '"', m.group(2)
            cands = ([os.path.normpath(os.path.join(rel, inc))] if quoted else []) + \
                [os.path.normpath(os.path.join(i, inc)) for i in incdirs]
            hit = next((c for c in cands if os.path.isfile(os.path.join(root, c))), None)
            if hit is None:
                continue  # generated (embedded shaders, gl tables) or system
            a, b = folder(src), folder(hit)
            if a != b and not hit.startswith("plugin/include/"):
                edges[a].add(b)
def strip(text):
    # comments, strings and char literals out (kept as spaces), preprocessor lines out
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("/*", i):
            j = text.find("*/", i + 2); j = n if j < 0 else j + 2
            out.append(" " * 1); i = j
        elif text.startswith("//", i):
            j = text.find("\n", i); j = n if j < 0 else j
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + c); i = j + 1
        else:
            out.append(c); i += 1
    s = "".join(out)
    lines, cont = [], False
    for l in s.split("\n"):
        if cont or l.lstrip().startswith("#"):
            cont = l.rstrip().endswith("\\"); lines.append(""); continue
        lines.append(l)
    return "\n".join(lines)

KEYWORDS = {"if", "for", "while", "switch", "return", "sizeof", "do", "else", "case", "_Alignof", "alignof",
            "_Static_assert", "defined", "__attribute__", "__typeof__", "typeof", "_Generic"}
DEF = re.compile(r"\b([A-Za-z_]\w*)\s*\(([^;{}]*)\)\s*(?:__attribute__\s*\(\(.*?\)\)\s*)*$", re.S)
CALL = re.compile(r"\b([A-Za-z_]\w*)\s*\(")

def functions(text):
    """(name, static, body) of every function defined at file scope."""
    s = strip(text)
    res, depth, start, i = [], 0, 0, 0
    while i < len(s):
        c = s[i]
        if c == "{" and depth == 0:
            head = s[start:i]
            m = DEF.search(head)
            j, d = i, 0
            while j < len(s):
                d += {"{": 1, "}": -1}.get(s[j], 0)
                if d == 0:
                    break
                j += 1
            if m and m.group(1) not in KEYWORDS and "=" not in head[m.start():]:
                pre = head[:m.start()]
                pre = pre[max(pre.rfind(";"), pre.rfind("}")) + 1:]
                res.append((m.group(1), "static" in pre.split(), s[i:j + 1]))
            i = j + 1
            start = i
            continue
        if c == ";" and depth == 0:
            start = i + 1
        i += 1
    return res

def module_edges(folder_files):
    """{module: {module it uses: why}} of one folder's files ({path: text})."""
    defs = collections.defaultdict(list)   # name -> [(module, path)] visible across files
    funcs = {}
    for p, t in folder_files.items():
        mod = os.path.splitext(os.path.basename(p))[0]
        fs = functions(t)
        funcs[p] = (mod, fs)
        for name, static, _ in fs:
            if not static or p.endswith(".h"):
                defs[name].append(mod)
    edges = collections.defaultdict(dict)
    for p, (mod, fs) in funcs.items():
        own = {n for n, _, _ in fs}
        for name, _, body in fs:
            for m in CALL.finditer(body):
                callee = m.group(1)
                if callee in own or callee not in defs:
                    continue
                for tgt in defs[callee]:
                    if tgt != mod:
                        edges[mod].setdefault(tgt, "%s calls %s" % (name, callee))
    return edges


def circles(edges):
    """The strongly connected parts of more than one node (Tarjan), each with its edges."""
    index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]
    nodes = sorted(set(edges) | {t for v in edges.values() for t in v})
    sys.setrecursionlimit(10000)
    def visit(v):
        index[v] = low[v] = counter[0]; counter[0] += 1; stack.append(v); on.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                visit(w); low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop(); on.discard(w); comp.append(w)
                if w == v: break
            if len(comp) > 1:
                sccs.append(sorted(comp))
    for v in nodes:
        if v not in index:
            visit(v)
    return [(c, ["%s -> %s%s" % (a, b, " (%s)" % edges[a][b] if edges[a][b] else "") for a in c
                 for b in sorted(edges[a]) if b in c]) for c in sccs]



found = 0
for folder in sorted(byfolder):
    for comp, notes in circles(module_edges(byfolder[folder])):
        found += 1
        print("%s: circle %s" % (folder, " <-> ".join(comp)))
        for n in notes:
            print("    " + n)
if check:
    if not found:
        print("no circle between the modules of a folder")
    sys.exit(1 if found else 0)
for a in sorted(edges):
    print("%-22s -> %s" % (a, ", ".join(sorted(edges[a]))))
