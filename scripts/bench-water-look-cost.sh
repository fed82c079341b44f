#!/bin/sh
# bench-water-look-cost.sh — the default scene's plugin.render CPU ms per frame (volfx-game's
# median over the frames after 5 warm-up ones) with two plugin builds, interleaved, ROUNDS
# rounds; prints one line a run and the median per build. The same host binary draws both.
# usage: scripts/bench-water-look-cost.sh GAME BEFORE.so AFTER.so [ROUNDS] [FRAMES] [SCENE]
set -eu
game=$1 before=$2 after=$3 rounds=${4:-3} frames=${5:-16} scene=${6:-sample_game/scenes/default.json}
out=$(mktemp -d)
for r in $(seq "$rounds"); do
    for which in before after; do
        so=$before; [ "$which" = after ] && so=$after
        ms=$("$game" --headless --scene "$scene" --frames "$frames" --size 640x360 --png "$out/x.png" \
             --progress 0 --plugin "$so" 2>/dev/null | sed -n 's/.*plugin.render \([0-9.]*\).*/\1/p')
        echo "round $r $which plugin.render $ms"
        echo "$ms" >> "$out/$which"
    done
done
for which in before after; do
    printf '%s median %s\n' "$which" "$(sort -n "$out/$which" | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}')"
done
rm -rf "$out"
