#!/bin/sh
# Regenerates the figures of docs/benchmarks-water.md: JSON lines (one per configuration, a
# "section" field added) into $OUT (default /tmp/bench-water.jsonl), then the markdown tables on
# stdout and the error-vs-time plot into docs/img/water-error-vs-time.png.
# Usage: scripts/bench-water.sh [build dir, default build]
#   PLOT_ONLY=1 scripts/bench-water.sh   re-prints the tables and plot from an existing $OUT
#   SECTION=repeat scripts/bench-water.sh   re-runs one section (table1, ablation, sweep,
#                                          repeat) into an existing $OUT, replacing its rows
# Every run uses flat shading (--disable 64): the shading pass is not what is compared here.
# llvmpipe budget: configurations expected over ~1 minute a frame are run with 1 frame and no
# warm-up, or skipped (listed in SKIPPED below and printed).
set -e
B=${1:-build}
OUT=${OUT:-/tmp/bench-water.jsonl}
PNG=${PNG:-docs/img/water-error-vs-time.png}
SKIPPED="paper 65536 at 512^2 (~5 min a frame); brute 4096 at 256^2 and 512^2, 16384 and 65536 at every size (2 to 60 min a frame: about 30 s at 4096 and 128^2, linear in particles and pixels)"
run() { # section, then volfx-bench metaballs options
  sec=$1; shift
  echo "  $sec: $*" >&2
  "$B/bench/volfx-bench" metaballs --reference "$@" 2>/dev/null | sed "s/^{/{\"section\":\"$sec\",/" >> "$OUT"
}
want() { [ -z "$SECTION" ] || [ "$SECTION" = "$1" ]; }
if [ -z "$PLOT_ONLY" ]; then
ninja -C "$B" >/dev/null
if [ -z "$SECTION" ]; then : > "$OUT"; else
  grep -v "\"section\":\"$SECTION\"" "$OUT" > "$OUT.tmp" || true; mv "$OUT.tmp" "$OUT"; fi
F="--disable 64"
if want table1; then
# --- Table 1 of the paper: 4,096 / 16,384 / 65,536 particles at 128^2 / 256^2 / 512^2
for n in 4096 16384 65536; do
  run table1 --method grid --particles $n --size 128 --size 256 --size 512 --frames 5 $F
done
run table1 --method paper --particles 4096 --size 128 --frames 4 $F
run table1 --method paper --particles 4096 --size 256 --size 512 --frames 1 --warmup 0 $F
run table1 --method paper --particles 16384 --particles 65536 --size 128 --frames 1 --warmup 0 $F
run table1 --method paper --particles 16384 --size 256 --size 512 --frames 1 --warmup 0 $F
run table1 --method paper --particles 65536 --size 256 --frames 1 --warmup 0 $F
run table1 --method brute --particles 4096 --size 128 --frames 1 --warmup 0 $F
fi
if want ablation; then
# --- ablation at 4,096 / 128^2: each technique off in turn (bits of VFX_WATER_NO_*)
for d in 0 1 2 4 8 16 32; do run ablation --method paper --particles 4096 --size 128 --frames 1 --disable $((d | 64)); done
for d in 0 1 2 3; do run ablation --method grid --particles 4096 --size 128 --frames 3 --disable $((d | 64)); done
fi
if want sweep; then
# --- quality knobs at 4,096 / 128^2: sample cap (Fig. 12: 16 / 32 / 54), step, refinement, pyramid
for m in paper grid; do
  fr=1; [ $m = grid ] && fr=3
  for c in 16 32 54 64; do run sweep --method $m --particles 4096 --size 128 --frames $fr --samples $c $F; done
  for w in 0.25 0.0625; do run sweep --method $m --particles 4096 --size 128 --frames $fr --step $w $F; done
  run sweep --method $m --particles 4096 --size 128 --frames $fr --disable $((32 | 64))
  for r in 1 6; do run sweep --method $m --particles 4096 --size 128 --frames $fr --refine $r $F; done
done
for l in 1 2 4 5; do run sweep --method paper --particles 4096 --size 128 --frames 1 --pyramid $l $F; done
for c in 16 32; do run sweep --method brute --particles 4096 --size 128 --frames 1 --warmup 0 --samples $c $F; done
fi
if want repeat; then
# --- the equal-error settings again, three interleaved rounds (4,096 / 128^2): run-to-run spread
for r in 1 2 3; do
  run repeat --method paper --particles 4096 --size 128 --frames 1 --samples 32 $F
  run repeat --method grid --particles 4096 --size 128 --frames 3 --samples 54 $F
  run repeat --method brute --particles 4096 --size 128 --frames 1 --warmup 0 --samples 16 $F
done
fi
fi
/usr/bin/python3 - "$OUT" "$PNG" "$SKIPPED" <<'PY'
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
png, skipped = sys.argv[2], sys.argv[3]
def passes(d):
    c = d.get("counters", {})
    p = [(k[len("water."):-len(".gpu_ms")], v) for k, v in c.items() if k.endswith(".gpu_ms") and k != "water.shade.gpu_ms"]
    return ", ".join("%s %.0f" % kv for kv in p) if p else "-"
def err(d):
    return "%.2f%% | %.2f%% | %.1e | %.1e" % (100 * d["hole_rate"], 100 * d["false_hit_rate"], d["dist_mean_rel_h"], d["dist_p99_rel_h"])
def cnt(d, k):
    c = d.get("counters", {})
    return "%.3g" % c[k] if k in c else "-"
def knobs(d):
    dis = d["disable"] & ~64
    return "cap %d, w h*%g, refine %s, pyr %d%s" % (d["max_samples"], d["step_h"], "0" if dis & 32 else d["refine"], d["pyramid"],
                                                   ", off %d" % dis if dis else "")
print("### Table 1 (paper layout; the paper's Table 1 fps on a GeForce 8800 GTX in parentheses)\n")
paper_fps = {(4096, 128): 60, (16384, 128): 37, (65536, 128): 12, (4096, 256): 35, (16384, 256): 21,
             (65536, 256): 7, (4096, 512): 11, (16384, 512): 10, (65536, 512): 3}
print("| method | particles | size | frames | frame ms p50 | fps | ms per pass (GPU timers) | hole rate | false hits | dist mean/h | dist p99/h | samples |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
t1 = [d for d in rows if d.get("section") == "table1"]
for d in sorted(t1, key=lambda d: (["paper", "grid", "brute"].index(d["method"]), d["particles"], d["width"])):
    print("| %s | %d | %d^2 | %d%s | %.0f | %.3g (GF8800: %d) | %s | %s | %s |" % (d["method"], d["particles"], d["width"], d["frames"],
          "" if d.get("warmup", 1) else " (no warm-up)", d["frame_ms"]["p50"], d["fps"], paper_fps[(d["particles"], d["width"])],
          passes(d), err(d), cnt(d, "water.samples")))
print("\nSkipped (over ~1 minute a frame on llvmpipe): %s.\n" % skipped)
print("Time ratios within this run, same configuration (frame ms of the other method / frame ms of grid):\n")
print("| particles | size | paper / grid | brute / grid |")
print("|---|---|---|---|")
by = {(d["method"], d["particles"], d["width"]): d for d in t1}
for n in (4096, 16384, 65536):
    for s in (128, 256, 512):
        g = by.get(("grid", n, s))
        if not g: continue
        r = lambda m: "%.1f" % (by[(m, n, s)]["frame_ms"]["p50"] / g["frame_ms"]["p50"]) if (m, n, s) in by else "-"
        print("| %d | %d^2 | %s | %s |" % (n, s, r("paper"), r("brute")))
print("\n### Ablation (4,096 particles, 128^2)\n")
names = {0: "all on", 1: "1 billboard init off", 2: "2 gap skip off", 4: "3 blending off (compute sum)", 8: "4 packing off (1 per texel)",
         16: "5 pyramid off", 32: "refinement off (eq. 5 only)", 3: "init and skip off"}
print("| method | switched off | frame ms p50 | vs all on | hole rate | false hits | dist mean/h | dist p99/h | samples | frags culled | potential frags | cells visited |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
ab = [d for d in rows if d.get("section") == "ablation"]
base = {d["method"]: d["frame_ms"]["p50"] for d in ab if d["disable"] == 64}
for d in ab:
    dis = d["disable"] & ~64
    gn = {1: "init: start at box entry", 2: "skip: fixed steps", 3: "both"}.get(dis, "all on") if d["method"] == "grid" else names[dis]
    print("| %s | %s | %.0f | %.2f | %s | %s | %s | %s | %s |" % (d["method"], gn, d["frame_ms"]["p50"], d["frame_ms"]["p50"] / base[d["method"]],
          err(d), cnt(d, "water.samples"), cnt(d, "water.fragments_culled"), cnt(d, "water.potential_fragments"), cnt(d, "water.grid_cells_visited")))
print("\n### Error against frame time over the quality knobs (4,096 particles, 128^2)\n")
print("| method | setting | frame ms p50 | hole rate | false hits | dist mean/h | dist p99/h | pixels at the cap | samples |")
print("|---|---|---|---|---|---|---|---|---|")
sw = [d for d in rows if d.get("section") == "sweep"]
for d in sw:
    print("| %s | %s | %.0f | %s | %s | %s |" % (d["method"], knobs(d), d["frame_ms"]["p50"], err(d), cnt(d, "water.pixels_sample_cap"), cnt(d, "water.samples")))
# equal error: for each method the cheapest sweep setting with no holes, no false hits and a p99
# distance error within the paper method's default p99
ref = [d for d in sw if d["method"] == "paper" and d["max_samples"] == 64 and d["step_h"] == 0.125 and d["disable"] == 64 and d["refine"] == 3 and d["pyramid"] == 3]
if ref:
    bound = ref[0]["dist_p99_rel_h"]
    print("\nEqual error (no holes, no false hits, dist p99 <= %.1e h, the paper method's default): cheapest setting per method\n" % bound)
    print("| method | setting | frame ms p50 | ratio to grid |")
    print("|---|---|---|---|")
    best = {}
    pool = sw + [d for d in t1 if d["particles"] == 4096 and d["width"] == 128]
    for d in pool:
        if d["hole_rate"] == 0 and d["false_hit_rate"] == 0 and d["dist_p99_rel_h"] <= bound * 1.0001:
            if d["method"] not in best or d["frame_ms"]["p50"] < best[d["method"]]["frame_ms"]["p50"]:
                best[d["method"]] = d
    for m in ("paper", "grid", "brute"):
        if m in best:
            d = best[m]
            print("| %s | %s | %.0f | %s |" % (m, knobs(d), d["frame_ms"]["p50"],
                  "%.1f" % (d["frame_ms"]["p50"] / best["grid"]["frame_ms"]["p50"]) if "grid" in best else "-"))
        else:
            print("| %s | none of the sweep's settings | - | - |" % m)
rp = [d for d in rows if d.get("section") == "repeat"]
if rp:
    print("\nRepeats of the equal-error settings (4,096 / 128^2), three interleaved rounds:\n")
    print("| round | paper cap 32 ms | grid cap 54 ms | brute cap 16 ms | paper / grid | brute / grid |")
    print("|---|---|---|---|---|---|")
    rounds = [rp[i:i + 3] for i in range(0, len(rp) - 2, 3)]
    pr, br = [], []
    for i, (p, g, b) in enumerate(rounds):
        pr.append(p["frame_ms"]["p50"] / g["frame_ms"]["p50"]); br.append(b["frame_ms"]["p50"] / g["frame_ms"]["p50"])
        print("| %d | %.0f | %.0f | %.0f | %.1f | %.1f |" % (i + 1, p["frame_ms"]["p50"], g["frame_ms"]["p50"], b["frame_ms"]["p50"], pr[-1], br[-1]))
    med = lambda v: sorted(v)[len(v) // 2]
    print("\nMedian ratios over the rounds: paper / grid %.1f, brute / grid %.1f." % (med(pr), med(br)))
try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for m, mk in (("paper", "o"), ("grid", "s"), ("brute", "^")):
        pts = [d for d in sw + [d for d in t1 if d["particles"] == 4096 and d["width"] == 128] if d["method"] == m]
        if not pts: continue
        ax[0].scatter([d["frame_ms"]["p50"] for d in pts], [max(d["dist_p99_rel_h"], 1e-6) for d in pts], marker=mk, label=m)
        ax[1].scatter([d["frame_ms"]["p50"] for d in pts], [100 * d["hole_rate"] for d in pts], marker=mk, label=m)
        for d in pts:
            ax[0].annotate(knobs(d).replace(", ", "\n").split("\n")[0] if d["max_samples"] != 64 else "", (d["frame_ms"]["p50"], max(d["dist_p99_rel_h"], 1e-6)), fontsize=6)
    for a in ax:
        a.set_xscale("log"); a.set_xlabel("frame ms (median, llvmpipe, 2 shared cores)"); a.legend()
    ax[0].set_yscale("log"); ax[0].set_ylabel("distance error p99 / h")
    ax[1].set_ylabel("hole rate (%)")
    fig.suptitle("Water: error vs frame time over cap, step, refinement, pyramid (4,096 particles, 128^2)")
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    print("\nPlot: %s" % png)
except Exception as e:
    print("\nNo plot: %s" % e)
PY
