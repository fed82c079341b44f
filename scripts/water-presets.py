#!/usr/bin/env python3
"""The water quality presets' cost and error (docs/water.md "Presets"): each preset (low, medium,
high, ultra; vfx_water_params.preset, scene key water.quality.preset) drawn by
`volfx-bench metaballs --preset P --reference` on the pool layout with a travelling wave (the
surface moves every frame, so temporal reuse meets motion as in a game), in interleaved rounds.
Cost: the bench's cpu_ms_per_frame (process CPU time, every llvmpipe thread, after a warm-up
frame); error: the last frame's distances against the float64 reference ray cast with the same
kernel (the anisotropic presets' reference builds its own kernels in double), hole rate, false
hits and the distance error relative to h. Medians over the rounds; the table is printed as
Markdown.

Usage: scripts/water-presets.py [--bench build/bench/volfx-bench] [--rounds 3] [--particles 3000]
       [--size 320x180] [--frames 3] [--wave 0.3] [--presets low,medium,high,ultra]"""
import argparse
import json
import statistics
import subprocess
import sys


def run(args, preset):
    w, h = args.size.split("x")
    cmd = [args.bench, "metaballs", "--layout", "pool", "--particles", str(args.particles), "--size", w,
           "--height", h, "--frames", str(args.frames), "--wave", str(args.wave), "--preset", preset, "--reference"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    line = [l for l in p.stdout.splitlines() if l.startswith("{")]
    if p.returncode or not line:
        sys.exit("%s failed (%d): %s" % (" ".join(cmd), p.returncode, (p.stdout + p.stderr)[-2000:]))
    return json.loads(line[-1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", default="build/bench/volfx-bench")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--particles", type=int, default=3000)
    ap.add_argument("--size", default="320x180")
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--wave", type=float, default=0.3)
    ap.add_argument("--presets", default="low,medium,high,ultra")
    args = ap.parse_args()
    presets = args.presets.split(",")
    res = {p: [] for p in presets}
    gl = "?"
    for r in range(args.rounds):
        for p in presets:  # interleaved: every round runs every preset once
            j = run(args, p)
            gl = j.get("gl_renderer", gl)
            res[p].append(j)
            print("round %d %s: %.1f ms CPU, holes %.5f, false %.5f, p99 %.2e h" %
                  (r, p, j["cpu_ms_per_frame"], j.get("hole_rate", float("nan")), j.get("false_hit_rate", float("nan")),
                   j.get("dist_p99_rel_h", float("nan"))), file=sys.stderr, flush=True)
    print("%s, %d particles (pool, wave %g), %s, %d frames, %d rounds interleaved\n" %
          (gl, args.particles, args.wave, args.size, args.frames, args.rounds))
    print("| preset | kernel | CPU ms / frame (median) | rounds | reference hits | hole rate | false hits | distance mean / p99 (h) |")
    print("|---|---|---|---|---|---|---|---|")
    for p in presets:
        js = res[p]
        cpu = [j["cpu_ms_per_frame"] for j in js]
        last = js[-1]
        med = lambda k: statistics.median(j.get(k, float("nan")) for j in js)
        print("| %s | %s | %.0f | %s | %d | %.5f | %.5f | %.1e / %.1e |" %
              (p, last["kernel"], statistics.median(cpu), " / ".join("%.0f" % c for c in cpu), last.get("ref_hits", 0),
               med("hole_rate"), med("false_hit_rate"), med("dist_mean_rel_h"), med("dist_p99_rel_h")))


if __name__ == "__main__":
    main()
