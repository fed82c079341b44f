#!/bin/bash
# invariance.sh — fingerprints of the default scene that a behaviour-preserving change (a file
# move, a split function, one pass API) must leave unchanged. Prints md5 sums of:
#   png     the default scene's image at frame 30, 320x180
#   beams   the beams' raw dump (--dump-raw beams, float PFM)
#   water   the water's raw distance dump, a function of every particle position: it changes
#           when the SPH/PBF state changes by one bit
#   volume  the volume's raw dump: NOT stable run to run today (two runs of 3c290ea differ), so
#           it is printed for information and is not part of the comparison
#   frame90 the image at frame 90 (the strike, foam and spray have begun)
# LP_NUM_THREADS=0: llvmpipe renders in the calling thread, so its output does not depend on
# thread scheduling. Compare the output before and after a change: every line must match.
# usage: scripts/invariance.sh [BUILD_DIR]   (default build)
set -euo pipefail
build=${1:-build}
game=$build/sample_game/volfx-game
scene=sample_game/scenes/default.json
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
run() { LP_NUM_THREADS=0 "$game" --headless --scene "$scene" --size 320x180 "$@" >/dev/null 2>&1; }
run --frames 30 --png "$tmp/f30.png" --dump-raw beams "$tmp/beams.pfm"
run --frames 30 --png "$tmp/w.png" --dump-raw water "$tmp/water.pfm"
run --frames 30 --png "$tmp/v.png" --dump-raw volume "$tmp/volume.pfm" || true
run --frames 90 --png "$tmp/f90.png"
for f in f30.png beams.pfm water.pfm volume.pfm f90.png; do
    if [ -f "$tmp/$f" ]; then printf '%-10s %s\n' "$f" "$(md5sum < "$tmp/$f" | cut -c1-32)"
    else printf '%-10s absent\n' "$f"; fi
done
