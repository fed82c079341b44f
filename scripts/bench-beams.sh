#!/bin/sh
# Regenerates the figures of docs/benchmarks-beams.md: closed form vs ray marching (8..120
# samples), 1/5/10 beams at 256^2 and 512^2, CPU float32, median of 5 runs. JSON lines to stdout.
# Usage: scripts/bench-beams.sh [build-dir]   (default build-beams)
set -e
B=${1:-build-beams}
ninja -C "$B" sample_game/volfx-bench >/dev/null
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
"$B/sample_game/volfx-bench" beams --reps 5 --json
