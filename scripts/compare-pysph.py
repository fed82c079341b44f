#!/usr/bin/python3
"""compare-pysph.py — the dam break of docs/simulation-validation.md (Martin & Moyce 1952, n^2 = 2,
a = 2.25 in) in PySPH and in volfx, interleaved, same particle count, tank and duration.

volfx: `volfx-bench sim --dam-break --res 20 --no-slip --solver wcsph|pbf --threads 2`
(a = 20 dx, 3,200 particles: a column a x 2a, 4 layers deep, in a tank 10a x 2.5a).
PySPH: the same 3,200 fluid particles (a/dx = 20, 4 layers deep), the tank's floor, end and
depth walls as 3 layers of boundary particles each (PySPH's boundary particles, its own wall
model, where ours are the semi-analytic walls of docs/simulation-wcsph.md), schemes WCSPH (Tait, gamma 7, c0 = 10 sqrt(2 g 2a), artificial
viscosity alpha 0.1), EDAC (alpha 0.1, PySPH's dam-break settings) and IISPH, cubic spline kernel, h = 1.3 dx, to T = 5.685 (t = 0.307 s).
Both are timed by process CPU time (volfx: its own figure, both worker threads; PySPH: single
threaded unless --openmp); the surge front (largest fluid x, over a) at Martin & Moyce's
times, and the mean compression max(0, rho/rho0 - 1) at the end.

Install PySPH (not needed by any test, so not in scripts/install-deps.sh):
    sudo apt-get install python3-pysph        # Debian 12: PySPH 1.0b1, WCSPH/IISPH/EDAC
IISPH lost particles through the boundary (\"LinkedListNNPS requires too many cells\") in the
first try, so the default schemes are wcsph,edac.
Run with the system Python (the Debian package):
    /usr/bin/python3 scripts/compare-pysph.py [--build build] [--reps 3] [--schemes wcsph,edac]
Prints one JSON line per run and a markdown table of medians (docs/simulation-validation.md, "A peer: PySPH and SPlisHSPlasH").
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

A = 0.05715
G = 9.81
MM_T = [0.832, 1.219, 1.997, 2.547, 3.345, 4.034, 4.418, 5.091, 5.685]
MM_Z = [1.217, 1.474, 2.292, 2.995, 4.134, 4.944, 5.881, 6.980, 7.945]


def run_volfx(build, solver):
    cmd = [os.path.join(build, "bench", "volfx-bench"), "sim", "--dam-break", "--res", "20",
           "--no-slip", "--solver", solver, "--threads", "2"]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    fronts, summary = [], None
    for line in out.splitlines():
        j = json.loads(line)
        if j.get("case") == "dam_break":
            fronts.append(j["Z"])
        elif j.get("case") == "dam_break_summary":
            summary = j
    return {"code": "volfx", "scheme": solver, "particles": summary["particles"],
            "cpu_s_per_sim_s": summary["cpu_s_per_simulated_s"],
            "mean_compression_end": None, "mean_compression_points": summary["mean_density_error_at_points"],
            "fronts": fronts}


def pysph_child(scheme_name, openmp):
    """Runs in a child process (PySPH's Application owns argv and its output folder)."""
    import numpy as np
    from pysph.base.kernels import CubicSpline
    from pysph.base.utils import get_particle_array
    from pysph.solver.application import Application
    from pysph.sph.iisph import IISPHScheme
    from pysph.sph.scheme import WCSPHScheme
    from pysph.sph.wc.edac import EDACScheme

    res = 20
    dx = A / res
    depth = 4 * dx
    h0 = 1.3 * dx
    rho0 = 1000.0
    c0 = 10.0 * math.sqrt(2 * G * 2 * A)
    Ts = math.sqrt(2 * G / A)
    t_end = MM_T[-1] / Ts
    targets = [t / Ts for t in MM_T]
    record = {"fronts": [], "times": []}

    class DamBreak(Application):
        def create_particles(self):
            # fluid: cell centres of the a x 2a x 4dx column, as rt_sph_add_block
            xs = (np.arange(res) + 0.5) * dx
            ys = (np.arange(2 * res) + 0.5) * dx
            zs = (np.arange(4) + 0.5) * dx
            x, y, z = np.meshgrid(xs, ys, zs, indexing="ij")
            m = rho0 * dx ** 3
            fluid = get_particle_array(name="fluid", x=x.ravel(), y=y.ravel(), z=z.ravel(),
                                       m=m, h=h0, rho=rho0)
            # tank: floor, the two end walls and the two depth walls (as ours: solid walls on
            # every side), 3 layers of boundary particles outside [0, 10a] x [0, 2.5a] x [0, 4dx]
            L, Hh = 10 * A, 2.5 * A
            bx = np.arange(-3, int(round(L / dx)) + 3) * dx + 0.5 * dx
            by = np.arange(-3, int(round(Hh / dx))) * dx + 0.5 * dx
            bz = np.arange(-3, 4 + 3) * dx + 0.5 * dx
            X, Y, Z = np.meshgrid(bx, by, bz, indexing="ij")
            X, Y, Z = X.ravel(), Y.ravel(), Z.ravel()
            solid = (Y < 0) | (X < 0) | (X > L) | (Z < 0) | (Z > depth)
            boundary = get_particle_array(name="boundary", x=X[solid], y=Y[solid], z=Z[solid],
                                          m=m, h=h0, rho=rho0)
            self.scheme.setup_properties([fluid, boundary])
            return [fluid, boundary]

        def create_scheme(self):
            if scheme_name == "edac":
                # entropically damped artificial compressibility (Ramachandran & Puri 2019), as
                # PySPH's own dam-break example sets it: free surface (pb = 0), clamped pressure
                return EDACScheme(["fluid"], ["boundary"], dim=3, c0=c0, nu=0.0, rho0=rho0, gy=-G, alpha=0.1,
                                  h=h0, clamp_p=True)
            if scheme_name == "iisph":
                # relaxed Jacobi (omega 0.5) to PySPH's default tolerance, 1% of rho0
                return IISPHScheme(["fluid"], ["boundary"], dim=3, rho0=rho0, gy=-G, nu=1e-6)
            return WCSPHScheme(["fluid"], ["boundary"], dim=3, rho0=rho0, c0=c0, h0=h0, hdx=1.3,
                               gy=-G, alpha=0.1, beta=0.0, gamma=7.0)

        def configure_scheme(self):
            dt = 0.25 * h0 / (1.1 * c0) if scheme_name in ("wcsph", "edac") else 0.1 * h0 / math.sqrt(2 * G * 2 * A)
            self.scheme.configure_solver(kernel=CubicSpline(dim=3), dt=dt, tf=t_end, pfreq=10 ** 9,
                                         adaptive_timestep=False)

        def post_step(self, solver):
            while targets and solver.t >= targets[0]:
                targets.pop(0)
                fl = self.particles[0]
                record["fronts"].append(float(fl.x.max() + 0.5 * dx) / A)
                record["times"].append(solver.t)

    out = tempfile.mkdtemp(prefix="pysph-db-")
    argv = ["--disable-output", "-d", out, "-q"]
    if openmp:
        argv.append("--openmp")
    app = DamBreak(fname="dam_break")
    c0t = time.process_time()
    app.run(argv)
    cpu = time.process_time() - c0t
    fl = app.particles[0]
    comp = float(np.mean(np.maximum(0.0, fl.rho / rho0 - 1.0)))
    print(json.dumps({"code": "pysph", "scheme": scheme_name, "particles": int(fl.get_number_of_particles()),
                      "cpu_s_per_sim_s": cpu / t_end, "mean_compression_end": comp,
                      "mean_compression_points": None, "fronts": record["fronts"]}))


def run_pysph(scheme, openmp):
    cmd = ["/usr/bin/python3", os.path.abspath(__file__), "--child", scheme] + (["--openmp"] if openmp else [])
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--schemes", default="wcsph,edac")
    ap.add_argument("--openmp", action="store_true")
    ap.add_argument("--child")
    a = ap.parse_args()
    if a.child:
        pysph_child(a.child, a.openmp)
        return 0
    runs = [("volfx", "wcsph"), ("volfx", "pbf")] + [("pysph", s) for s in a.schemes.split(",") if s]
    results = {r: [] for r in runs}
    for rep in range(a.reps):  # interleaved: every configuration once per repetition
        for code, scheme in runs:
            r = run_volfx(a.build, scheme) if code == "volfx" else run_pysph(scheme, a.openmp)
            r["rep"] = rep
            print(json.dumps(r), flush=True)
            results[(code, scheme)].append(r)
    print("\n| code, scheme | particles | CPU s per simulated s (median) | mean compression | front error vs Martin & Moyce, worst |")
    print("|---|---:|---:|---:|---:|")
    for (code, scheme), rs in results.items():
        cpu = statistics.median(r["cpu_s_per_sim_s"] for r in rs)
        f = rs[0]["fronts"]
        worst = max((abs(z - m) / m for z, m in zip(f, MM_Z)), default=float("nan"))
        comp = rs[0]["mean_compression_end"] if rs[0]["mean_compression_end"] is not None else rs[0]["mean_compression_points"]
        print(f"| {code} {scheme} | {rs[0]['particles']} | {cpu:.3f} | {100 * comp:.2f}% | {100 * worst:.1f}% ({len(f)} points) |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
