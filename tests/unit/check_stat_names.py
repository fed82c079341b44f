#!/usr/bin/env python3
"""docs/stats.md is the one list of stat names: every name the plugin's code sets (a literal in
volfx_stat_set/add) and every pass it times (a literal in a pass desc's .name or in
volfx_composite_targets) is listed there, every listed name is set or timed somewhere, and
docs/*.md, README.md and volfx.h mention no stat-like name that is neither. With a bench
executable, the names a default-scene frame and a GRID water frame really return are checked too.
usage: check_stat_names.py SOURCE_ROOT [volfx-bench]"""
import glob, json, os, re, subprocess, sys

root = sys.argv[1]
bench = sys.argv[2] if len(sys.argv) > 2 else None
NS = r"(?:water|beams|volume|gpu)\.[a-z0-9_]+"
SFX = (".gpu_ms", ".gpu_depth")

code = ""
fail = []
for f in glob.glob(os.path.join(root, "plugin", "**", "*.c"), recursive=True):
    text = open(f).read()
    code += text + "\n"
    # one pass API: every timed pass begins with volfx_pass_begin (gpu/pass.h), so its name is a
    # desc's .name; the timer under it is called by pass.c alone
    if os.path.basename(f) not in ("pass.c", "gpu.c") and re.search(r"volfx_gpu_timer_(?:begin|end)\(", text):
        fail.append("%s calls the GPU timer directly: begin passes with volfx_pass_begin" % f)
stats = set(re.findall(r'volfx_stat_(?:set|add)\(\s*ctx\s*,\s*"(%s)"' % NS, code))
passes = set()
for expr in re.findall(r"\.name\s*=\s*([^,}]*)", code):  # a pass desc's name, maybe a ?: of two
    passes |= set(re.findall(r'"(%s)"' % NS, expr))
passes |= set(re.findall(r'volfx_composite(?:_targets)?\(\s*ctx\s*,[^,]+,\s*"(%s)"' % NS, code))

doc = open(os.path.join(root, "docs", "stats.md")).read()
counters_part, _, passes_part = doc.partition("## GPU passes")
doc_stats = set(re.findall(r"^\| `(%s)` \|" % NS, counters_part, re.M))
doc_passes = set(re.findall(r"^\| `(%s)` \|" % NS, passes_part, re.M))

for n in sorted(stats - doc_stats):
    fail.append("set in plugin/ but not in docs/stats.md: " + n)
for n in sorted(doc_stats - stats):
    fail.append("in docs/stats.md but set nowhere: " + n)
for n in sorted(passes - doc_passes):
    fail.append("timed pass not in docs/stats.md: " + n)
for n in sorted(doc_passes - passes):
    fail.append("pass in docs/stats.md that no code times: " + n)

known = doc_stats | doc_passes | {p + s for p in doc_passes for s in SFX}
# scene-file keys share the namespaces (water.path, volume.transfer): the ones scene-format.md
# documents are not stats
scene_keys = set(re.findall(r"(?<![\w./-])(%s(?:\.[a-z0-9_]+)*)" % NS,
                            open(os.path.join(root, "docs", "scene-format.md")).read()))
files = glob.glob(os.path.join(root, "docs", "*.md")) + [os.path.join(root, "README.md"),
        os.path.join(root, "plugin", "include", "volfx", "volfx.h")]
KEYS_DOCS = {"scene-format.md", "simulation.md", "tetvol-input.md"}
EXT = {"md", "c", "h", "comp", "frag", "vert", "glsl", "json", "jsonl", "png", "pfm", "py", "sh", "vtu", "txt"}
for f in files:
    if f.endswith("benchmarks.md") or "benchmarks-" in f:
        continue  # generated from runs: the names there came from get_stats
    for m in re.finditer(r"(?<![\w./-])(%s(?:\.[a-z0-9_]+)*)(?![\w/-])" % NS, open(f).read()):
        name = m.group(1).rstrip(".")
        is_key = name in scene_keys or any(k.startswith(name + ".") for k in scene_keys)
        if name.split(".")[-1] in EXT or name in known or (is_key and not name.endswith(SFX)):
            continue
        if os.path.basename(f) in KEYS_DOCS and not name.endswith(SFX):
            continue  # scene keys (water.path, volume.transfer, ...) share the namespaces
        # "water.pyramid/potential/update/skip" style lists are checked by the first name only
        fail.append("%s mentions '%s', which is no stat or pass" % (os.path.relpath(f, root), name))

seen = set()
if bench:
    for args in (["frame", "--size", "64x36", "--frames", "5", "--json"],
                 ["metaballs", "--method", "grid", "--particles", "1024", "--size", "32", "--frames", "4"]):
        r = subprocess.run([bench] + args, capture_output=True, text=True)
        if r.returncode != 0:
            fail.append("volfx-bench %s failed: %s" % (" ".join(args), r.stderr[-500:]))
            continue
        for line in r.stdout.splitlines():
            if line.startswith("{"):
                o = json.loads(line)
                seen |= set((o.get("stats") or o.get("counters") or {}).keys())
    for n in sorted(seen - known):
        fail.append("returned by get_stats but not in docs/stats.md: " + n)
print("%d stats, %d passes listed; %d names seen at run time" % (len(doc_stats), len(doc_passes), len(seen)))
for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
