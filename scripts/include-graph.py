#!/usr/bin/env python3
"""include-graph.py [SOURCE_ROOT] — which folder's sources include which other folder's headers:
each quoted #include resolved against the including file's folder, then the build's include
directories (meson.build); generated headers (embedded shaders, the GL table) and system headers
are left out, and so is <volfx/volfx.h>, which every folder may include. docs/architecture.md
("What each folder may include") is this graph with its rules: run it after moving code."""
import os, re, sys, collections
root = sys.argv[1] if len(sys.argv) > 1 else "."
incdirs = ["plugin/include", "plugin/lab", "plugin", "runtime", "shaders", "tetra", "reference", "sample_game", "tests/common", "bench"]
def folder(p):
    parts = p.split("/")
    if parts[0] in ("plugin", "runtime", "tests", "shaders") and len(parts) > 2:
        return "/".join(parts[:2])
    return parts[0]
edges = collections.defaultdict(set)
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
for a in sorted(edges):
    print("%-22s -> %s" % (a, ", ".join(sorted(edges[a]))))
