#!/bin/sh
# Regenerates the figures of docs/benchmarks-water.md (JSON lines on stdout).
# Usage: scripts/bench-water.sh [build dir, default build-water]
set -e
B=${1:-build-water}
ninja -C "$B" >/dev/null
# Brute-force baseline only (the paper's pipeline is not written yet): llvmpipe sizes that
# finish in about a minute; 16,384 / 65,536 particles and 512^2 are skipped there.
"$B"/sample_game/volfx-bench metaballs --particles 576 --particles 4096 --size 64 --size 128 --frames 3 --reference
