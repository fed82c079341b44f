#!/usr/bin/env bash
# Long-run stability (issue 8): the sample game headless for N frames (default 100,000) with
# resident memory and live GL object counts sampled every 1,000 frames; fails when RSS grows by
# more than 1 MB or any GL object count grows after warm-up (the first sample after frame 1,000).
# Not a CI test (it takes a long time on llvmpipe). Usage: scripts/long-run.sh [frames] [game args]
# The issue-8 run: scripts/long-run.sh 100000 --scene sample_game/scenes/long-run.json --size 64x36
# (every effect of the default scene, cut down so llvmpipe does ~30 fps: about an hour).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-100000}
shift || true
build=${VFX_BUILD_DIR:-build}
ninja -C "$build" >/dev/null
out=${VFX_LONG_RUN_LOG:-long-run.log}
"$build/sample_game/volfx-game" --headless --frames "$frames" --mem-every 1000 --size 320x180 "$@" | tee "$out"
python3 - "$out" <<'PY'
import re, sys
rows = [l for l in open(sys.argv[1]) if l.startswith("mem frame")]
if len(rows) < 3:
    print("long-run: too few samples"); sys.exit(1)
def parse(l):
    m = re.match(r"mem frame (\d+) rss_kb (\d+) gl_objects (\d+)", l)
    return int(m[1]), int(m[2]), int(m[3])
base = parse(rows[1])
last = parse(rows[-1])
peak = max(parse(r)[1] for r in rows[1:])
print(f"long-run: frames {last[0]}, rss after warm-up {base[1]} kB, at end {last[1]} kB, peak {peak} kB, "
      f"growth {last[1]-base[1]} kB; GL objects {base[2]} -> {last[2]}")
sys.exit(0 if (last[1] - base[1]) <= 1024 and last[2] <= base[2] else 1)
PY
