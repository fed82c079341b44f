#!/usr/bin/python3
"""sim-goals.py — issue 22's goals for the fluid simulation, measured in one run.

Runs, in this order (each a command a reader can run alone):
  volfx-bench sim --pool 16384 --frames 60 --solver wcsph,pbf,pbf-jacobi --settle 120
      the default scene's pool (tank, spacing and paddle of default.json), the three solvers
      stepped in turn every frame: CPU per 1/60 s frame (process CPU of both worker threads,
      median over the frames), the WCSPH / PBF ratio, mean compression, max speed over frames 2-30
  volfx-bench sim --pool 65536 --frames 20 --solver wcsph,pbf,pbf-jacobi --settle 120
  volfx-bench sim --pool 16384 --frames 300 --no-paddle --solver pbf --settle 120
      the closed pool: max speed over frames 2-300 and at 300, energy growth between samples
  volfx-bench sim --dam-break --res 20 --no-slip --solver wcsph|pbf --threads 2
      Martin & Moyce (1952): the worst front error over the 9 tabulated times
  volfx-game --frames 30 --size 640x360 --csv ... --png ...   (headless, the default scene)
      sim.max_speed over frames 2-30, sim.density_error, vfx.sim.sph; the frame-30 image

Usage: /usr/bin/python3 scripts/sim-goals.py [--build build-release] [--game-build build]
       [--settle 120] [--skip-game] [--png FILE]
Prints one markdown table (docs/simulation.md, "Measured figures") and the machine line.
"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile


def bench(build, args):
    cmd = [os.path.join(build, "bench", "volfx-bench"), "sim"] + args
    print("$ volfx-bench sim " + " ".join(args), file=sys.stderr)
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return [json.loads(l) for l in out.splitlines() if l.startswith("{")]


def by_solver(rows):
    return {r["solver"]: r for r in rows if "solver" in r}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build-release")
    ap.add_argument("--game-build", default="build")
    ap.add_argument("--settle", type=int, default=120,
                    help="--settle N for the pool runs: the game's default water.simulation.settle_steps (0: none)")
    ap.add_argument("--skip-game", action="store_true")
    ap.add_argument("--png", default="sim-goals-frame30.png")
    a = ap.parse_args()
    settle = ["--settle", str(a.settle)] if a.settle > 0 else []
    load0 = open("/proc/loadavg").read().split()[0]

    p16 = by_solver(bench(a.build, ["--pool", "16384", "--frames", "60", "--solver", "wcsph,pbf,pbf-jacobi"] + settle))
    p64 = by_solver(bench(a.build, ["--pool", "65536", "--frames", "20", "--solver", "wcsph,pbf,pbf-jacobi"] + settle))
    rest = by_solver(bench(a.build, ["--pool", "16384", "--frames", "300", "--no-paddle", "--solver", "pbf"] + settle))
    dam = {}
    for solver in ("wcsph", "pbf"):
        rows = bench(a.build, ["--dam-break", "--res", "20", "--no-slip", "--solver", solver, "--threads", "2"])
        dam[solver] = next(r for r in rows if r.get("case") == "dam_break_summary")
        dam[solver]["errors"] = [r["error_pct"] for r in rows if r.get("case") == "dam_break"]

    game = None
    if not a.skip_game:
        with tempfile.TemporaryDirectory() as d:
            csv_path = os.path.join(d, "g.csv")
            cmd = [os.path.join(a.game_build, "sample_game", "volfx-game"), "--frames", "30", "--size", "640x360",
                   "--csv", csv_path, "--png", a.png]
            print("$ volfx-game " + " ".join(cmd[1:]), file=sys.stderr)
            subprocess.run(cmd, check=True, capture_output=True, text=True)
            rows = list(csv.DictReader(open(csv_path)))
        speeds = [float(r["sim.max_speed"]) for r in rows]
        dens = [float(r["sim.density_error"]) for r in rows]
        sph = sorted(float(r["vfx.sim.sph"]) for r in rows)
        game = {"vmax_2_30": max(speeds[1:30]), "at": 2 + speeds[1:30].index(max(speeds[1:30])),
                "dens_mean": sum(dens) / len(dens), "dens_max": max(dens), "sph_ms": sph[len(sph) // 2],
                "settle": rows[0].get("sim.settle_steps", "n/a")}
    load1 = open("/proc/loadavg").read().split()[0]

    def f(x, n=1):
        return f"{x:.{n}f}"

    w, p, j = p16["wcsph"], p16["pbf"], p16["pbf-jacobi"]
    W, P, J = p64["wcsph"], p64["pbf"], p64["pbf-jacobi"]
    r = rest["pbf"]
    print("| measure | WCSPH | PBF (default: 5 Chebyshev iterations) | PBF, 6 plain Jacobi iterations (the old default) | goal |")
    print("|---|---:|---:|---:|---|")
    print(f"| 16,384 ({p['particles']:,} particles): CPU ms per 1/60 s frame, paddle | {f(w['cpu_ms_per_frame_median'])} "
          f"({f(w['steps_per_frame'])} substeps) | {f(p['cpu_ms_per_frame_median'])} | {f(j['cpu_ms_per_frame_median'])} | <= 8 |")
    print(f"| 16,384: WCSPH / PBF, CPU | | {f(w['cpu_ms_per_frame_median'] / p['cpu_ms_per_frame_median'], 2)}x | "
          f"{f(w['cpu_ms_per_frame_median'] / j['cpu_ms_per_frame_median'], 2)}x | >= 10x |")
    print(f"| 65,536 ({P['particles']:,}): CPU ms per frame | {f(W['cpu_ms_per_frame_median'])} ({f(W['steps_per_frame'])} substeps) "
          f"| {f(P['cpu_ms_per_frame_median'])} | {f(J['cpu_ms_per_frame_median'])} | <= 32 |")
    print(f"| 65,536: WCSPH / PBF, CPU | | {f(W['cpu_ms_per_frame_median'] / P['cpu_ms_per_frame_median'], 2)}x | "
          f"{f(W['cpu_ms_per_frame_median'] / J['cpu_ms_per_frame_median'], 2)}x | |")
    print(f"| mean compression, 16,384, frames 1-60 | {f(100 * w['mean_compression'], 2)}% | {f(100 * p['mean_compression'], 2)}% "
          f"| {f(100 * j['mean_compression'], 2)}% | <= 1% |")
    print(f"| mean compression, 65,536, frames 1-20 | {f(100 * W['mean_compression'], 2)}% | {f(100 * P['mean_compression'], 2)}% "
          f"| {f(100 * J['mean_compression'], 2)}% | |")
    print(f"| max speed, frames 2-30, paddle (bench pool) | {f(w['max_speed_frames_2_30'], 2)} m/s | {f(p['max_speed_frames_2_30'], 2)} m/s "
          f"| {f(j['max_speed_frames_2_30'], 2)} m/s | <= 1.26 m/s |")
    print(f"| closed pool ({r['particles']:,}), 300 frames: max speed over 2-300 / at 300 | | "
          f"{f(r['max_speed_frames_2_on'], 3)} / {f(r['max_speed_last'], 3)} m/s | | <= 0.05 m/s |")
    print(f"| closed pool: largest energy rise between samples 10 frames apart | | {r['energy_growth_max']:.2g} of E0 | | <= 1% |")
    if "settle_steps" in p:
        print(f"| settle before frame 0 (16,384, paddle): steps, CPU s, max speed at its end | | {p['settle_steps']}, "
              f"{f(p['settle_cpu_s'], 2)} s, {f(p['settle_max_speed_last'], 3)} m/s | | short, counted, logged |")
    print(f"| dam break a/dx = 20, worst of 9 points vs Martin & Moyce | {f(dam['wcsph']['max_abs_error_pct'], 2)}% | "
          f"{f(dam['pbf']['max_abs_error_pct'], 2)}% | | within 10% |")
    print(f"| dam break: CPU s per simulated s | {f(dam['wcsph']['cpu_s_per_simulated_s'], 2)} | "
          f"{f(dam['pbf']['cpu_s_per_simulated_s'], 2)} | | |")
    if game:
        print(f"| game (640x360, default scene): sim.max_speed over frames 2-30 | | {f(game['vmax_2_30'], 2)} m/s "
              f"(frame {game['at']}) | | <= 1.26 m/s |")
        print(f"| game: sim.density_error mean / max, frames 1-30 | | {f(100 * game['dens_mean'], 2)}% / "
              f"{f(100 * game['dens_max'], 2)}% | | <= 1% |")
        print(f"| game: vfx.sim.sph median (wall ms, the profiler's figure) | | {f(game['sph_ms'])} | | |")
    cpu = subprocess.run(["sh", "-c", "grep -m1 'model name' /proc/cpuinfo | cut -d: -f2"], capture_output=True,
                         text=True).stdout.strip()
    print(f"\nMachine: {cpu}, {os.cpu_count()} cores; load average {load0} at the start, {load1} at the end; "
          f"dam-break PBF fronts {', '.join('%+.1f' % e for e in dam['pbf']['errors'])}%.")
    if game:
        print(f"Frame-30 image: {a.png}.")


if __name__ == "__main__":
    main()
