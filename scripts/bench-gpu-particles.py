#!/usr/bin/env python3
"""CPU cost of the plugin's calls with the particles as CPU arrays and as GL buffers
(--gpu-particles): the default scene (16,384 particles) at 640x360, the two configurations run
interleaved, ROUNDS times each, FRAMES frames a run; per configuration the median over every
measured frame (the first WARM of each run dropped: program compiles, the first upload) of the
game profiler's plugin.update, plugin.render and host.gpu_particles (the game's own copy of its
CPU simulation into the GL buffer), in ms of the calling thread's wall clock, and the ratios.
usage: scripts/bench-gpu-particles.py [build dir, default build] (env ROUNDS, FRAMES, WARM)"""
import csv, os, statistics, subprocess, sys, tempfile

build = sys.argv[1] if len(sys.argv) > 1 else "build"
rounds, frames, warm = (int(os.environ.get(k, d)) for k, d in (("ROUNDS", 3), ("FRAMES", 12), ("WARM", 2)))
game = os.path.join(build, "sample_game", "volfx-game")
cols = ("plugin.update", "plugin.render", "host.gpu_particles")
samples = {cfg: {c: [] for c in cols} for cfg in ("cpu", "gpu")}
with tempfile.TemporaryDirectory() as tmp:
    for r in range(rounds):
        for cfg in ("cpu", "gpu"):
            out = os.path.join(tmp, f"{cfg}{r}.csv")
            cmd = [game, "--headless", "--frames", str(frames), "--size", "640x360", "--csv", out,
                   "--png", os.path.join(tmp, "x.png")] + (["--gpu-particles"] if cfg == "gpu" else [])
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            with open(out) as f:
                for row in list(csv.DictReader(f))[warm:]:
                    for c in cols:
                        if row.get(c):
                            samples[cfg][c].append(float(row[c]))
            print(f"round {r + 1}/{rounds} {cfg} done", file=sys.stderr)
med = {cfg: {c: statistics.median(v) if v else 0.0 for c, v in s.items()} for cfg, s in samples.items()}
print(f"default scene, 640x360, {rounds} interleaved rounds x {frames - warm} frames; median ms")
print("| | plugin.update | plugin.render | update + render | host.gpu_particles |")
print("|---|---|---|---|---|")
for cfg in ("cpu", "gpu"):
    m = med[cfg]
    print(f"| {cfg} arrays | {m['plugin.update']:.3f} | {m['plugin.render']:.1f} | "
          f"{m['plugin.update'] + m['plugin.render']:.1f} | {m['host.gpu_particles']:.3f} |")
c, g = med["cpu"], med["gpu"]
ratio = lambda a, b: a / b if b else float("nan")
print(f"gpu / cpu: update {ratio(g['plugin.update'], c['plugin.update']):.2f}, render "
      f"{ratio(g['plugin.render'], c['plugin.render']):.3f}, update + render "
      f"{ratio(g['plugin.update'] + g['plugin.render'], c['plugin.update'] + c['plugin.render']):.3f}")
