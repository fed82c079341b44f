#!/usr/bin/env python3
"""CPU cost of the water's screen-space reflections (docs/water-look.md, "Reflections' cost"): runs
volfx-game on a scene with and without VFX_WATER_NO_SSR (the scene flag "ssr" added to
water.quality.disable), interleaved A B A B ..., and prints each run's process CPU time (all
llvmpipe threads: user + sys of the child) per frame, the medians and their ratio, and the SSR
hits of the last frame.
usage: bench-water-ssr.py [BUILD_DIR] [SCENE] [FRAMES] [ROUNDS] [WxH]"""
import json, os, re, resource, statistics, subprocess, sys, tempfile

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(root, "build")
scene = sys.argv[2] if len(sys.argv) > 2 else os.path.join(root, "sample_game/scenes/water-only.json")
frames = int(sys.argv[3]) if len(sys.argv) > 3 else 12
rounds = int(sys.argv[4]) if len(sys.argv) > 4 else 3
size = sys.argv[5] if len(sys.argv) > 5 else "640x360"
game = os.path.join(build, "sample_game/volfx-game")

d = json.load(open(scene))
d.setdefault("water", {}).setdefault("quality", {}).setdefault("disable", []).append("ssr")
tmp = tempfile.NamedTemporaryFile("w", suffix=".json", delete=False, dir=os.path.dirname(os.path.abspath(scene)))
json.dump(d, tmp)
tmp.close()


def run(path):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = subprocess.run([game, "--scene", path, "--frames", str(frames), "--size", size, "--png", os.devnull],
                         capture_output=True, text=True, check=True).stdout
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    hits = re.search(r"water\.ssr_hits=([0-9.e+]+)", out)
    return 1000.0 * cpu / frames, float(hits.group(1)) if hits else -1


try:
    res = {"ssr": [], "no_ssr": []}
    hits = {}
    for r in range(rounds):
        for name, path in (("ssr", scene), ("no_ssr", tmp.name)):
            ms, h = run(path)
            res[name].append(ms)
            hits[name] = h
            print(f"round {r} {name}: {ms:.1f} ms CPU per frame, water.ssr_hits {h:.0f}", flush=True)
    a, b = statistics.median(res["ssr"]), statistics.median(res["no_ssr"])
    print(json.dumps({"scene": os.path.basename(scene), "frames": frames, "size": size, "rounds": rounds,
                      "cpu_ms_per_frame_ssr": res["ssr"], "cpu_ms_per_frame_no_ssr": res["no_ssr"],
                      "median_ssr": round(a, 1), "median_no_ssr": round(b, 1), "ratio": round(a / b, 3),
                      "ssr_hits": hits}))
finally:
    os.unlink(tmp.name)
