#!/usr/bin/env python3
"""check_shader_tables.py LIB SHADER_ROOT --plugin FILE... --host FILE... [--lab FILE...]
The plugin ships its own shaders and none of the sample host's or the lab's: every file of the
plugin's table is in LIB's bytes (embed.py keeps the text verbatim), and no host-only or lab-only
file (listed in the host's or the lab's table, not in the plugin's) is."""
import os
import sys

lib, root = sys.argv[1], sys.argv[2]
args = sys.argv[3:]
plugin = args[args.index("--plugin") + 1: args.index("--host")]
host = args[args.index("--host") + 1: args.index("--lab") if "--lab" in args else len(args)]
lab = args[args.index("--lab") + 1:] if "--lab" in args else []
data = open(lib, "rb").read()
rel = lambda f: os.path.relpath(os.path.abspath(f), os.path.abspath(root))


def embedded(f):
    # embed.py keeps the text verbatim: a file is in the binary when each of its lines is
    # (C string concatenation joins them); a line shorter than 24 bytes proves nothing alone
    lines = [l for l in open(f, encoding="utf-8").read().split("\n") if len(l.strip()) >= 24]
    return bool(lines) and all(l.encode() in data for l in lines)


plugin_rel = {rel(f) for f in plugin}
bad = [rel(f) for f in host if rel(f) not in plugin_rel and embedded(f)]
bad_lab = [rel(f) for f in lab if rel(f) not in plugin_rel and embedded(f)]
missing = [rel(f) for f in plugin if not embedded(f) and any(len(l.strip()) >= 24 for l in open(f))]
if missing:
    print("%s: the plugin's own shaders are not found in it (the check is blind): %s" % (lib, ", ".join(missing)))
if bad:
    print("%s carries the host's shaders: %s" % (lib, ", ".join(bad)))
if bad_lab:
    print("%s carries the lab's shaders: %s" % (lib, ", ".join(bad_lab)))
if missing or bad or bad_lab:
    sys.exit(1)
print("%s: %d plugin shaders embedded, none of the host's %d nor the lab's %d" % (
    lib, len(plugin), len([f for f in host if rel(f) not in plugin_rel]), len([f for f in lab if rel(f) not in plugin_rel])))
