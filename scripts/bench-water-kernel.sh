#!/bin/sh
# TILE's kernel, isotropic (the seed's) against anisotropic (Yu & Turk 2013, docs/water.md
# "Anisotropic kernels"), on the pool layout at 640x360: ROUNDS interleaved rounds (isotropic,
# anisotropic, for each particle count), CPU time of the process per frame (all llvmpipe
# threads), medians; the 3,000-particle runs also against the float64 reference (with the
# reference's own anisotropic kernels). JSON lines into $OUT, the markdown table on stdout.
# Usage: scripts/bench-water-kernel.sh [build dir, default build]   (ROUNDS=3, FRAMES=3)
set -e
B=${1:-build}
OUT=${OUT:-/tmp/bench-water-kernel.jsonl}
ROUNDS=${ROUNDS:-3}
FRAMES=${FRAMES:-3}
ninja -C "$B" >/dev/null
: > "$OUT"
for n in 3000 16384; do
  ref=""
  [ "$n" = 3000 ] && ref="--reference"
  r=1
  while [ "$r" -le "$ROUNDS" ]; do
    for k in isotropic anisotropic; do
      echo "  round $r: $n particles, $k" >&2
      "$B/bench/volfx-bench" metaballs --layout pool --particles "$n" --size 640 --height 360 --frames "$FRAMES" \
        --method tile --kernel "$k" $ref 2>/dev/null | sed "s/^{/{\"round\":$r,/" >> "$OUT"
    done
    r=$((r + 1))
  done
done
python3 - "$OUT" <<'EOF'
import json, statistics, sys
rows = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
print("| particles | kernel | CPU ms / frame (median) | rounds | / isotropic | aniso pass GPU ms | sphere tests | dense pixels | hole rate | dist p99/h |")
print("|---|---|---|---|---|---|---|---|---|---|")
for n in sorted({r["particles"] for r in rows}):
    med = {}
    for k in ("isotropic", "anisotropic"):
        rs = [r for r in rows if r["particles"] == n and r["kernel"] == k]
        med[k] = statistics.median(r["cpu_ms_per_frame"] for r in rs)
    for k in ("isotropic", "anisotropic"):
        rs = [r for r in rows if r["particles"] == n and r["kernel"] == k]
        c = rs[-1].get("counters", {})
        hole = "%.2f%%" % (100 * rs[-1]["hole_rate"]) if "hole_rate" in rs[-1] else "-"
        p99 = "%.1e" % rs[-1]["dist_p99_rel_h"] if "dist_p99_rel_h" in rs[-1] else "-"
        print("| %d | %s | %.0f | %s | %.2f | %s | %.3g | %d | %s | %s |" % (
            n, k, med[k], ", ".join("%.0f" % r["cpu_ms_per_frame"] for r in rs), med[k] / med["isotropic"],
            "%.0f" % c["water.aniso.gpu_ms"] if "water.aniso.gpu_ms" in c else "-",
            c.get("water.tile_sphere_tests", 0), c.get("water.tile_dense_pixels", 0), hole, p99))
print()
print("GL_RENDERER: %s" % rows[0]["gl_renderer"])
EOF
