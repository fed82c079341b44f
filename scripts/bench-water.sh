#!/bin/sh
# Regenerates the figures of docs/benchmarks-water.md: JSON lines into $OUT (default
# /tmp/bench-water.jsonl), then the markdown tables on stdout.
# Usage: scripts/bench-water.sh [build dir, default build-water]
set -e
B=${1:-build-water}
OUT=${OUT:-/tmp/bench-water.jsonl}
ninja -C "$B" >/dev/null
V="$B/sample_game/volfx-bench metaballs --frames 3 --reference"
: > "$OUT"
# Table 1 subset that llvmpipe finishes in seconds (16,384 / 65,536 particles, 256^2 / 512^2 skipped)
for m in paper brute; do
  $V --method $m --particles 576 --particles 4096 --size 64 --size 128 >> "$OUT"
done
# ablation: each technique off in turn (bits of VFX_WATER_NO_*), 4,096 particles at 64^2
for d in 0 1 2 4 8 16 32; do $V --particles 4096 --size 64 --disable $d >> "$OUT"; done
# sample cap sweep (the paper's Fig. 12: 16 / 32 / 54 / 64), 4,096 particles at 128^2
for c in 16 32 54 64; do
  $V --particles 4096 --size 128 --samples $c >> "$OUT"
  $V --method brute --particles 4096 --size 128 --samples $c >> "$OUT"
done
/usr/bin/python3 - "$OUT" <<'PY'
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
print("| method | disable | cap | particles | size | frame ms p50 | hole rate | false hits | dist mean/h | dist p99/h | samples | frags culled |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
for d in rows:
    c = d.get("counters", {})
    print("| %s | %d | %d | %d | %d^2 | %.0f | %.2f%% | %.2f%% | %.1e | %.1e | %s | %s |" % (
        d["method"], d["disable"], d["max_samples"], d["particles"], d["width"], d["frame_ms"]["p50"],
        100 * d["hole_rate"], 100 * d["false_hit_rate"], d["dist_mean_rel_h"], d["dist_p99_rel_h"],
        "%.3g" % c["water.samples"] if "water.samples" in c else "-",
        "%.3g" % c["water.fragments_culled"] if "water.fragments_culled" in c else "-"))
PY
