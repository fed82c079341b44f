#!/usr/bin/env python3
"""The game's default scene's water, method by method, in interleaved rounds (docs/benchmarks-water.md,
"Default scene"): each configuration is a copy of sample_game/scenes/default.json with
water.quality.method / disable set, run headless with beams and the volume off, once for F1 and
once for F2 frames (--frames F1,F2); one more pair with the water simulated but not drawn
(--hide-water) gives the rest of the frame (simulation, host scene). The water's CPU time per
frame is the process's CPU time (every llvmpipe thread; getrusage of the child) of frames F1+1..F2,
(cpu(F2) - cpu(F1)) / (F2 - F1), minus the same of the hidden-water pair of that round: start-up
and shader compilation cancel, and the simulation is the same in every run (same scene, same
fixed steps). plugin.render is the game's own median wall time of the render call (F2 run).

Usage: scripts/water-default-scene.py [--build build] [--rounds 3] [--frames 6] [--size 640x360]
       [--configs paper,tile,no_temporal,no_half,no_both,low,medium,high,ultra]
The PNG of every configuration's last frame goes to /tmp/water-default-NAME.png.
--callgrind: instead, each configuration once under valgrind --tool=callgrind with llvmpipe in the
calling thread (LP_NUM_THREADS=0), instructions collected inside the plugin's render call only
(--toggle-collect=plugin_render, one dump per call): instructions per render call, frame by frame
(the first compiles the shaders); repeatable counts, minutes per configuration."""
import argparse
import glob
import json
import os
import re
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONFIGS = {
    "paper": ("paper (seed 000)", "paper", []),
    "tile": ("**tile (ours), all on**", "tile", []),
    "no_temporal": ("tile, NO_TEMPORAL", "tile", ["temporal"]),
    "no_half": ("tile, NO_HALF_RES", "tile", ["half_res"]),
    "no_both": ("tile, NO_TEMPORAL + NO_HALF_RES", "tile", ["temporal", "half_res"]),
    # the quality presets (water.quality.preset; medium is the default)
    "low": ("preset low", "tile", [], "low"),
    "medium": ("**preset medium (the default)**", "tile", [], "medium"),
    "high": ("preset high", "tile", [], "high"),
    "ultra": ("preset ultra", "tile", [], "ultra"),
}


def run(cmd):
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.monotonic() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode:
        sys.exit("%s failed (%d): %s" % (" ".join(cmd), p.returncode, (p.stdout + p.stderr)[-2000:]))
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    out = p.stdout + p.stderr
    m = re.search(r"plugin\.render ([0-9.]+)", out)
    stats = dict(re.findall(r"(water\.[a-z_.]+)=([0-9.e+-]+)", out))
    gl = re.search(r"GL context: ([^,]+, [^,]+)", out)
    return cpu, wall, float(m.group(1)) if m else float("nan"), stats, gl.group(1) if gl else "?"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--frames", default="2,6")
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--configs", default="paper,tile,no_temporal,no_half,no_both")
    ap.add_argument("--callgrind", action="store_true")
    a = ap.parse_args()
    names = a.configs.split(",")
    f1, f2 = (int(x) for x in a.frames.split(","))
    if not 0 < f1 < f2:
        sys.exit("--frames F1,F2 with 0 < F1 < F2")
    for n in names:
        if n not in CONFIGS:
            sys.exit("unknown configuration %s (known: %s)" % (n, ", ".join(CONFIGS)))
    src = os.path.join(ROOT, "sample_game", "scenes", "default.json")
    scene = json.load(open(src))
    game = os.path.join(a.build, "sample_game", "volfx-game")
    base = [game, "--headless", "--size", a.size, "--no-beams", "--no-volume"]
    files = {}
    for n in names:
        s = json.loads(json.dumps(scene))
        q = s["water"].setdefault("quality", {})
        q["method"] = CONFIGS[n][1]
        if CONFIGS[n][2]:
            q["disable"] = CONFIGS[n][2]
        if len(CONFIGS[n]) > 3:
            q["preset"] = CONFIGS[n][3]
        # next to default.json: its relative paths resolve the same
        f = os.path.join(ROOT, "sample_game", "scenes", ".water-default-%d-%s.json" % (os.getpid(), n))
        json.dump(s, open(f, "w"))
        files[n] = f
    if a.callgrind:
        try:
            callgrind(a, names, files, base, f2)
        finally:
            for f in files.values():
                os.remove(f)
        return
    res = {n: [] for n in names + ["none"]}
    gl = "?"
    try:
        for r in range(a.rounds):
            for n in names + ["none"]:
                cmd = base + (["--scene", files[n], "--png", "/tmp/water-default-%s.png" % n] if n != "none"
                              else ["--scene", src, "--hide-water", "--png", "/tmp/water-default-none.png"])
                c1 = run(cmd + ["--frames", str(f1)])[0]
                cpu, wall, render, stats, g = run(cmd + ["--frames", str(f2)])
                gl = g if g != "?" else gl
                res[n].append((cpu - c1, wall, render, stats))
                print("round %d %-12s cpu %.2f s (frames %d-%d) plugin.render %.1f ms" % (r + 1, n, cpu - c1, f1 + 1,
                      f2, render), file=sys.stderr)
    finally:
        for f in files.values():
            os.remove(f)
    nf = f2 - f1
    none = [x[0] for x in res["none"]]
    print("`%s`; %d rounds, frames %d-%d at %s, GL_RENDERER %s, %d cores; the water hidden (simulated, not drawn): "
          "%.0f ms CPU a frame (median)\n" % (" ".join(sys.argv), a.rounds, f1 + 1, f2, a.size, gl, os.cpu_count(),
                                             1000 * statistics.median(none) / nf))
    water = {n: [1000 * (x[0] - none[r]) / nf for r, x in enumerate(res[n])] for n in names}
    med = {n: statistics.median(v) for n, v in water.items()}
    print("| water | water CPU ms / frame (median) | rounds | / paper | plugin.render ms (median of the game's) |"
          " found | samples | sphere tests | reused / fallback | upsampled / re-marched |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for n in names:
        st = res[n][-1][3]

        def g(k):
            return "%.3g" % float(st[k]) if k in st else "-"
        print("| %s | %.0f | %s | %s | %.0f | %s | %s | %s | %s / %s | %s / %s |" % (
            CONFIGS[n][0], med[n], ", ".join("%.0f" % x for x in water[n]),
            "%.3f (1/%.1f)" % (med[n] / med["paper"], med["paper"] / med[n]) if "paper" in med and med[n] > 0 else "-",
            statistics.median(x[2] for x in res[n]), g("water.pixels_found"), g("water.samples"),
            g("water.tile_sphere_tests"), g("water.tile_temporal_reused"), g("water.tile_temporal_fallback"),
            g("water.tile_half_upsampled"), g("water.tile_half_remarched")))


def callgrind(a, names, files, base, frames):
    env = dict(os.environ, LP_NUM_THREADS="0")
    counts = {}
    for n in names:
        out = "/tmp/water-default-cg-%d-%s.out" % (os.getpid(), n)
        for f in glob.glob(out + "*"):
            os.remove(f)
        cmd = ["valgrind", "--tool=callgrind", "--collect-atstart=no", "--toggle-collect=plugin_render",
               "--dump-after=plugin_render", "--callgrind-out-file=" + out] + base + \
              ["--scene", files[n], "--frames", str(frames), "--png", "/tmp/water-default-cg-%s.png" % n]
        p = subprocess.run(cmd, capture_output=True, text=True, env=env)
        if p.returncode:
            sys.exit("%s failed: %s" % (" ".join(cmd), p.stderr[-2000:]))
        dumps = sorted(glob.glob(out + ".*"), key=lambda f: int(f.rsplit(".", 1)[1]))
        counts[n] = []
        for d in dumps:
            m = re.search(r"^summary: (\d+)", open(d).read(), re.M)
            counts[n].append(int(m.group(1)) if m else 0)
        print("%-12s %s" % (n, " ".join("%.3g" % c for c in counts[n])), file=sys.stderr)
    print("`%s`: instructions (valgrind callgrind, LP_NUM_THREADS=0) inside plugin_render per frame; "
          "frame 1 compiles the shaders\n" % " ".join(sys.argv))
    nf = max(len(v) for v in counts.values())
    print("| water | " + " | ".join("frame %d" % (k + 1) for k in range(nf)) + " | frames 2-%d mean | / tile |" % nf)
    print("|---|" + "---|" * (nf + 2))
    mean = {n: statistics.mean(v[1:]) if len(v) > 1 else float("nan") for n, v in counts.items()}
    for n in names:
        print("| %s | %s | %.3g | %s |" % (CONFIGS[n][0], " | ".join("%.3g" % c for c in counts[n]), mean[n],
                                        "%.2f" % (mean[n] / mean["tile"]) if "tile" in mean else "-"))


if __name__ == "__main__":
    main()
