#!/usr/bin/env python3
"""bench-beams-cost.py — the default scene's beams cost (issue 25 item 5), against a build of the
round's starting main: `volfx-game --no-water --no-volume` at 640x360 on llvmpipe.

--callgrind (the cost figure, repeatable under load): each build once under valgrind
  --tool=callgrind with llvmpipe in the calling thread (LP_NUM_THREADS=0), instructions collected
  inside plugin_render only, one dump per call; frame 1 compiles shaders, so frames 2..N are the
  mean compared.
default: CPU time, interleaved: rounds of (base, new) runs, plugin.render ms per frame from the
  game's --csv with LP_NUM_THREADS=0 (llvmpipe's work in the render call's thread, so its wall time
  is that thread's CPU time when not preempted), median over frames 2..N and rounds.
--falloff hard,smooth: the default scene with every beam's falloff set to each (scenes written to
  /tmp), each game run on each: the smooth/hard ratio.
Usage: scripts/bench-beams-cost.py [--callgrind] [--frames N] [--rounds R] [--falloff hard,smooth]
       BASE_GAME NEW_GAME [...]
"""
import argparse, csv, glob, json, os, re, statistics, subprocess, sys, tempfile


def base_args(frames, scene):
    a = ["--no-water", "--no-volume", "--size", "640x360", "--frames", str(frames)]
    return a + (["--scene", scene] if scene else [])


def callgrind(game, frames, scene, tag):
    env = dict(os.environ, LP_NUM_THREADS="0")
    out = "/tmp/bench-beams-cg-%d-%s.out" % (os.getpid(), tag)
    for f in glob.glob(out + "*"):
        os.remove(f)
    cmd = ["valgrind", "--tool=callgrind", "--collect-atstart=no", "--toggle-collect=plugin_render",
           "--dump-after=plugin_render", "--callgrind-out-file=" + out, game] + base_args(frames, scene) + \
          ["--png", "/tmp/bench-beams-cg-%s.png" % tag]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode:
        sys.exit("%s failed: %s" % (" ".join(cmd), p.stderr[-2000:]))
    dumps = sorted(glob.glob(out + ".*"), key=lambda f: int(f.rsplit(".", 1)[1]))
    counts = []
    for d in dumps:
        m = re.search(r"^summary: (\d+)", open(d).read(), re.M)
        counts.append(int(m.group(1)) if m else 0)
        os.remove(d)
    stats = re.findall(r"(beams\.[a-z_]+)=([0-9.e+]+)", p.stdout + p.stderr)
    return counts, dict(stats)


def cpu_run(game, frames, scene):
    env = dict(os.environ, LP_NUM_THREADS="0")
    with tempfile.NamedTemporaryFile(suffix=".csv", delete=False) as f:
        path = f.name
    p = subprocess.run([game] + base_args(frames, scene) + ["--csv", path, "--png", "/tmp/bench-beams-cpu.png"],
                       capture_output=True, text=True, env=env)
    if p.returncode:
        sys.exit("%s failed: %s" % (game, p.stderr[-2000:]))
    rows = list(csv.DictReader(open(path)))
    os.remove(path)
    return [float(r["plugin.render"]) for r in rows[1:]]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("games", nargs="+", help="volfx-game binaries; the first is the reference")
    ap.add_argument("--callgrind", action="store_true")
    ap.add_argument("--frames", type=int, default=4)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--scene", action="append", default=None, help="scene per game (else the default scene)")
    ap.add_argument("--falloff", default=None, help="comma list of falloffs for the default scene's beams")
    a = ap.parse_args()
    scenes = a.scene or [None] * len(a.games)
    if len(scenes) == 1:
        scenes = scenes * len(a.games)
    if a.falloff:
        root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
        d = json.load(open(os.path.join(root, "sample_game/scenes/default.json")))
        games, scenes = [], []
        for f in a.falloff.split(","):
            for b in d["beams"]:
                b["falloff"] = f
            path = "/tmp/bench-beams-%s-%d.json" % (f, os.getpid())
            json.dump(d, open(path, "w"))
            for g in a.games:
                games.append(g)
                scenes.append(path)
        a.games = games
    load = open("/proc/loadavg").read().split()[:3]
    print("# machine: %s; load %s" % (open("/proc/cpuinfo").read().split("model name")[1].split(":")[1].split("\n")[0].strip(),
                                      " ".join(load)))
    res = {}
    if a.callgrind:
        for i, g in enumerate(a.games):
            counts, stats = callgrind(g, a.frames, scenes[i], str(i))
            mean = statistics.mean(counts[1:]) if len(counts) > 1 else float("nan")
            res[i] = mean
            print(json.dumps({"game": g, "scene": scenes[i], "instructions_per_render": counts,
                              "mean_frames_2_on": mean, "ratio": mean / res[0], "stats": stats}))
    else:
        per = {i: [] for i in range(len(a.games))}
        for _ in range(a.rounds):
            for i, g in enumerate(a.games):
                per[i] += cpu_run(g, a.frames, scenes[i])
        for i, g in enumerate(a.games):
            med = statistics.median(per[i])
            res[i] = med
            print(json.dumps({"game": g, "scene": scenes[i], "plugin_render_ms_median": med,
                              "ratio": med / res[0], "samples": len(per[i])}))
    print("# load at end %s" % " ".join(open("/proc/loadavg").read().split()[:3]))


if __name__ == "__main__":
    main()
