#!/bin/sh
# bench-water-look-cost.sh — the default scene's plugin.render cost per frame with two builds,
# each its own game and plugin (an ABI change means one host cannot load both), interleaved,
# ROUNDS rounds; prints one line a run and the median per build. LP_NUM_THREADS=0: llvmpipe works
# on the calling thread, so plugin.render_thread_cpu (the render call's CPU time on that thread;
# a game without it: plugin.render, wall time) measures the plugin's CPU cost under any load.
# Each game prints the median over the frames after its 5 warm-up ones.
# usage: scripts/bench-water-look-cost.sh BEFORE_GAME AFTER_GAME [ROUNDS] [FRAMES] [BEFORE_SCENE] [AFTER_SCENE]
#   (the scenes default to each build's own sample_game/scenes/default.json, found beside its game)
set -eu
before=$1 after=$2 rounds=${3:-3} frames=${4:-12}
scene_of() { echo "$(dirname "$1")/../../sample_game/scenes/default.json"; }
bscene=${5:-$(scene_of "$before")} ascene=${6:-$(scene_of "$after")}
out=$(mktemp -d)
for r in $(seq "$rounds"); do
    for which in before after; do
        game=$before scene=$bscene
        [ "$which" = after ] && game=$after scene=$ascene
        line=$(LP_NUM_THREADS=0 "$game" --headless --scene "$scene" --frames "$frames" --size 640x360 \
               --png "$out/x.png" --progress 0 2>/dev/null | grep '^cpu ms')
        wall=$(echo "$line" | sed -n 's/.*plugin.render \([0-9.]*\).*/\1/p')
        cpu=$(echo "$line" | sed -n 's/.*plugin.render_thread_cpu \([0-9.]*\).*/\1/p')
        echo "round $r $which plugin.render wall $wall thread_cpu ${cpu:-none}"
        echo "${cpu:-$wall}" >> "$out/$which"
    done
done
for which in before after; do
    printf '%s median %s\n' "$which" "$(sort -n "$out/$which" | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}')"
done
rm -rf "$out"
