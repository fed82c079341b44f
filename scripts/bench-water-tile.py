#!/usr/bin/env python3
"""TILE's ablation against the other water methods, in interleaved rounds (docs/benchmarks-water.md,
"Method TILE"): every configuration runs once per round, in turn, and the table gives the median
over the rounds of the process's CPU time per frame (volfx-bench metaballs cpu_ms_per_frame, every
llvmpipe thread), ratios within the run, the errors against the float64 reference and the counters.

Usage: scripts/bench-water-tile.py [--build build] [--rounds 3] [--frames 3] [--layout layers|pool]
       [--particles 4096] [--size 128] [--height H] [--wave A] [--configs NAME,NAME,...]
       [--jsonl FILE] [--no-reference]
Configurations (names for --configs): see CONFIGS below. JSON lines of every run go to --jsonl."""
import argparse
import json
import statistics
import subprocess
import sys

F = 64  # flat shading: the shading is not what is compared
NO_LOCAL, NO_SUB, NO_TILES, NO_TEMPORAL, NO_HALF, NO_FINISH = 1 << 8, 1 << 9, 1 << 10, 1 << 12, 1 << 13, 1 << 7
CONFIGS = [
    ("paper", "paper (seed 000), finishing on", "paper", 0),
    ("paper_nofinish", "paper, NO_FINISH (the seed exactly)", "paper", NO_FINISH),
    ("brute", "brute (baseline)", "brute", 0),
    ("grid", "grid (baseline)", "grid", 0),
    ("tile", "**tile (ours), all on**", "tile", 0),
    ("tile_aniso", "tile, anisotropic kernel (the scenes' default; Yu & Turk)", "tile", 0),
    ("no_temporal", "tile, NO_TEMPORAL (every ray from its first sphere entry)", "tile", NO_TEMPORAL),
    ("no_half", "tile, NO_HALF_RES (every pixel marched)", "tile", NO_HALF),
    ("no_both", "tile, NO_TEMPORAL + NO_HALF_RES", "tile", NO_TEMPORAL | NO_HALF),
    ("no_local", "tile, NO_LOCAL_LIST (tile list summed per sample)", "tile", NO_LOCAL),
    ("no_subdivide", "tile, NO_SUBDIVIDE (plain steps)", "tile", NO_SUB),
    ("no_tiles", "tile, NO_TILES (every pixel reads every particle)", "tile", NO_TILES),
]
# configurations that choose TILE's kernel (volfx-bench --kernel; the others get the ABI's default,
# the seed's isotropic kernel)
KERNEL = {"tile_aniso": "anisotropic"}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--frames", type=int, default=3)
    ap.add_argument("--layout", default="layers")
    ap.add_argument("--particles", type=int, default=4096)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--height", type=int, default=0)
    ap.add_argument("--wave", type=float, default=0.0)
    ap.add_argument("--configs", default=",".join(c[0] for c in CONFIGS))
    ap.add_argument("--jsonl", default="/tmp/bench-water-tile.jsonl")
    ap.add_argument("--no-reference", action="store_true")
    a = ap.parse_args()
    names = a.configs.split(",")
    cfgs = [c for c in CONFIGS if c[0] in names]
    if len(cfgs) != len(names):
        sys.exit("unknown configuration in --configs (known: %s)" % ", ".join(c[0] for c in CONFIGS))
    runs = {c[0]: [] for c in cfgs}
    out = open(a.jsonl, "w")
    for r in range(a.rounds):
        for name, _, method, bits in cfgs:
            cmd = [a.build + "/bench/volfx-bench", "metaballs", "--method", method, "--disable", str(bits | F),
                   "--layout", a.layout, "--particles", str(a.particles), "--size", str(a.size),
                   "--frames", str(a.frames)]
            if a.height:
                cmd += ["--height", str(a.height)]
            if name in KERNEL:
                cmd += ["--kernel", KERNEL[name]]
            if a.wave:
                cmd += ["--wave", str(a.wave)]
            # the reference once (the last round): it does not change between rounds
            if not a.no_reference and r == a.rounds - 1:
                cmd += ["--reference"]
            p = subprocess.run(cmd, capture_output=True, text=True)
            if p.returncode:
                sys.exit("%s failed: %s" % (" ".join(cmd), p.stderr[-2000:]))
            j = json.loads(p.stdout.strip().splitlines()[-1])
            j["config"] = name
            j["round"] = r
            out.write(json.dumps(j) + "\n")
            out.flush()
            runs[name].append(j)
            print("round %d %-14s cpu %.1f ms/frame" % (r + 1, name, j["cpu_ms_per_frame"]), file=sys.stderr)
    j0 = runs[cfgs[0][0]][0]
    print("`%s` rounds %d, frames %d, %s layout, %d particles, %dx%d, wave %g; GL_RENDERER %s\n" % (
        " ".join(sys.argv), a.rounds, a.frames, a.layout, a.particles, j0["width"], j0["height"], a.wave,
        j0["gl_renderer"]))
    med = {n: statistics.median(x["cpu_ms_per_frame"] for x in v) for n, v in runs.items()}
    base_t = med.get("tile")
    base_p = med.get("paper")
    print("| method | CPU ms / frame (median) | rounds | / tile | / paper | hole rate | false hits | dist mean/h |"
          " dist p99/h | samples | sphere tests | reused / fallback | samples saved | upsampled / re-marched |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for name, label, _, _ in cfgs:
        v = runs[name]
        last = v[-1]
        c = last.get("counters", {})

        def g(k, fmt="%.3g"):
            return fmt % c[k] if k in c else "-"

        def e(k, fmt, scale=1.0):
            return fmt % (scale * last[k]) if k in last else "-"
        print("| %s | %.0f | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s / %s | %s | %s / %s |" % (
            label, med[name], ", ".join("%.0f" % x["cpu_ms_per_frame"] for x in v),
            "%.2f" % (med[name] / base_t) if base_t else "-", "%.3f" % (med[name] / base_p) if base_p else "-",
            e("hole_rate", "%.2f%%", 100), e("false_hit_rate", "%.2f%%", 100), e("dist_mean_rel_h", "%.1e"),
            e("dist_p99_rel_h", "%.1e"), g("water.samples"), g("water.tile_sphere_tests"),
            g("water.tile_temporal_reused"), g("water.tile_temporal_fallback"), g("water.tile_temporal_samples_saved"),
            g("water.tile_half_upsampled"), g("water.tile_half_remarched")))


if __name__ == "__main__":
    main()
