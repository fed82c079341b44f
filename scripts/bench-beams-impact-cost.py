#!/usr/bin/env python3
"""bench-beams-impact-cost.py — what the beams' impacts and lights cost (issue 25, docs/beams.md
"What impacts and lights cost"): interleaved rounds of two games (a build before them, a build
with them) on one scene, `--no-water --no-volume --size 320x180` with LP_NUM_THREADS=0 (llvmpipe
renders in the calling thread, so a step's ms is that thread's CPU time); prints the medians of
host.scene, plugin.render and the impact passes' GPU timers over frames 3..N of all rounds.
Usage: scripts/bench-beams-impact-cost.py BASE_GAME NEW_GAME SCENE.json FRAMES ROUNDS"""
import csv, os, statistics, subprocess, sys, tempfile
games = {"base": sys.argv[1], "new": sys.argv[2]}
scene, frames, rounds = sys.argv[3], int(sys.argv[4]), int(sys.argv[5])
cols = ["host.scene", "plugin.render", "beams.integrate.gpu_ms", "beams.impact_hit.gpu_ms",
        "beams.impact_step.gpu_ms", "beams.impact_draw.gpu_ms"]
acc = {g: {c: [] for c in cols} for g in games}
env = dict(os.environ, LP_NUM_THREADS="0")
for r in range(rounds):
    for g, exe in games.items():
        path = tempfile.mktemp(suffix=".csv")
        subprocess.run([exe, "--headless", "--no-water", "--no-volume", "--size", "320x180", "--frames", str(frames),
                        "--scene", scene, "--csv", path, "--png", "/tmp/bench-beams-impact-%s.png" % g],
                       env=env, capture_output=True, check=True)
        rows = list(csv.DictReader(open(path)))[3:]
        os.remove(path)
        for c in cols:
            acc[g][c] += [float(x[c]) for x in rows if x.get(c) not in (None, "")]
for g in games:
    print(g, " ".join("%s=%.2f(n=%d)" % (c, statistics.median(v), len(v)) for c, v in acc[g].items() if v))
