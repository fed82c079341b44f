#!/usr/bin/env python3
"""The game's --trace on the real plugin, read as Perfetto lays it out: on each thread two
slices are disjoint or nested; the water march loop's passes lie inside water.march; every GPU
pass inside a GPU frame; GPU frames one after another; no ".gpu_ms" in slice names; process and
thread names, categories and the counter tracks present.
usage: check_trace.py volfx-game"""
import json, os, subprocess, sys, tempfile

EPS = 0.002  # us: the trace's %.3f
game = sys.argv[1]
with tempfile.TemporaryDirectory() as d:
    trace = os.path.join(d, "t.json")
    # a scene on the published water method: its march loop nests passes inside water.march
    scene = os.path.join(os.environ.get("VFX_SOURCE_ROOT", "."), "sample_game", "scenes", "volume-showcase.json")
    r = subprocess.run([game, "--headless", "--scene", scene, "--frames", "8", "--size", "96x54", "--png", os.path.join(d, "g.png"),
                        "--trace", trace], capture_output=True, text=True)
    if r.returncode != 0:
        print(r.stdout, r.stderr)
        sys.exit(1)
    ev = json.load(open(trace))["traceEvents"]
meta = [e for e in ev if e["ph"] == "M"]
xs = [e for e in ev if e["ph"] == "X"]
cs = {e["name"] for e in ev if e["ph"] == "C"}
fail = []
if not any(e["name"] == "process_name" for e in meta):
    fail.append("no process_name")
if {e.get("tid") for e in meta if e["name"] == "thread_name"} != {1, 2}:
    fail.append("thread names missing")
for want in ("fps", "particles", "water holes (rays at the sample cap)", "volume cells skipped (ERT)"):
    if want not in cs:
        fail.append("no counter track " + want)
for e in xs:
    if ".gpu_ms" in e["name"]:
        fail.append("slice name with .gpu_ms: " + e["name"])
    if e.get("cat") not in ("frame", "cpu", "gpu"):
        fail.append("slice without a category: " + e["name"])
over = 0
for tid in (1, 2):
    t = sorted((e for e in xs if e["tid"] == tid), key=lambda e: (e["ts"], -e["dur"]))
    stack = []
    for e in t:
        while stack and e["ts"] >= stack[-1] - EPS:
            stack.pop()
        if stack and e["ts"] + e["dur"] > stack[-1] + EPS:
            over += 1
            if over < 5:
                fail.append("overlap on tid %d at %s" % (tid, e["name"]))
        stack.append(e["ts"] + e["dur"])
def inside(c, p):
    return p["ts"] <= c["ts"] + EPS and c["ts"] + c["dur"] <= p["ts"] + p["dur"] + EPS
gpu = [e for e in xs if e["tid"] == 2]
frames = [e for e in gpu if e["name"].startswith("gpu frame ")]
marches = [e for e in gpu if e["name"] == "water.march"]
if len(frames) < 3:
    fail.append("%d GPU frames in 8 frames" % len(frames))
for a, b in zip(frames, frames[1:]):
    if b["ts"] + EPS < a["ts"] + a["dur"]:
        fail.append("GPU frames overlap: %s %s" % (a["name"], b["name"]))
loop = 0
for e in gpu:
    if e in frames:
        continue
    if not any(inside(e, f) for f in frames):
        fail.append(e["name"] + " outside every GPU frame")
    if e["name"] in ("water.pyramid", "water.potential", "water.update", "water.skip"):
        loop += 1
        if not any(inside(e, m) for m in marches):
            fail.append(e["name"] + " outside water.march")
if loop == 0:
    fail.append("no water march loop passes in the trace")
print("%d slices (%d on the GPU, %d GPU frames, %d march-loop passes), %d overlaps" % (len(xs), len(gpu), len(frames), loop, over))
for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
