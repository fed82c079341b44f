#!/usr/bin/env python3
"""Writes the markdown of docs/benchmarks-gpu.md from the JSON files scripts/gpu-bench.sh wrote.
usage: gpu-bench-md.py DIR > docs/benchmarks-gpu.md     (DIR: gpu-bench.sh's --out)
       gpu-bench-md.py --none > docs/benchmarks-gpu.md  (the page before any GPU run)
scripts/run-benchmarks.sh lists that page in docs/benchmarks.md with the other parts."""
import json, os, sys

HEAD = """# GPU figures

`scripts/gpu-bench.sh --prepare` here, then `scripts/gpu-bench.sh --out DIR` on a machine with an
NVIDIA GPU (the device tool: carry `[".gl"]`), then `scripts/gpu-bench-md.py DIR >
docs/benchmarks-gpu.md` and `scripts/run-benchmarks.sh --index-only`. Frame times are the
host's wall clock around update+render to `glFinish`, medians; "ms per pass" are the plugin's GPU
timer queries (`<pass>.gpu_ms`) of the last frame. Water runs use flat shading (`--disable 64`).
"""


def fmt(v, d=2):
    return "-" if v is None else ("%.*f" % (d, v) if isinstance(v, (int, float)) else str(v))


def passes(r, prefix):
    c = r.get("counters") or r.get("stats") or {}
    p = [(k[len(prefix):-len(".gpu_ms")], v) for k, v in c.items()
         if k.startswith(prefix) and k.endswith(".gpu_ms")]
    return ", ".join("%s %.2f" % (k, v) for k, v in p) or "-"


def table(out, title, cmds, late, header, rows):
    out.append("## " + title + "\n")
    out.append("Commands: " + "; ".join("`%s`" % c for c in cmds) + ".\n" if cmds else "")
    if late:
        out.append("Not finished in the time budget: " + "; ".join("`%s`" % c for c in late) + ".\n")
    out.append("| " + " | ".join(header) + " |")
    out.append("|" + "---|" * len(header))
    out.extend("| " + " | ".join(r) + " |" for r in rows)
    out.append("")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    if sys.argv[1] == "--none":
        print(HEAD + "\nNo GPU has run this code yet: no task so far was lent a GPU machine. The tables "
              "(water Table 1 with 262,144 and 1,048,576 particles at 1920x1080, every water method, "
              "beams 100 and 1,000 at 1920x1080, the default scene at 1920x1080) go here, with the "
              "GPU and driver named.")
        return
    d = sys.argv[1]
    load = lambda n: json.load(open(os.path.join(d, n)))
    g = load("gpu.json")
    out = [HEAD, "Machine: GL_RENDERER `%s`; %s; %s, %s cores; EGL platform `%s`; %s s for the whole run.\n"
           % (g.get("gl_renderer"), g.get("nvidia_smi") or "no nvidia-smi", g.get("cpu"), g.get("cores"),
              g.get("egl_platform"), g.get("seconds"))]
    t = load("tests.json")["tests"]
    out.append("GL tests on that platform: %d ok, %d failed%s, %d skipped.\n" % (
        sum(x["result"] == "ok" for x in t), sum(x["result"] == "failed" for x in t),
        "".join(" (%s)" % x["name"] for x in t if x["result"] == "failed"), sum(x["result"] == "skipped" for x in t)))
    w = load("water-table1.json")
    table(out, "Water, Table 1 of seed 000 (paper method)", w["commands"], w["not_finished"],
          ["particles", "size", "frames", "frame ms p50", "fps", "ms per pass"],
          [[str(r["particles"]), "%dx%d" % (r["width"], r["height"]), str(r["frames"]), fmt(r["frame_ms"]["p50"]),
            fmt(r.get("fps"), 1), passes(r, "water.")] for r in w["rows"]])
    m = load("water-methods.json")
    table(out, "Water, every method on the same particles, camera and size", m["commands"], m["not_finished"],
          ["method", "particles", "size", "frame ms p50", "hole rate", "dist p99 / h", "ms per pass"],
          [[r["method"], str(r["particles"]), "%dx%d" % (r["width"], r["height"]), fmt(r["frame_ms"]["p50"]),
            fmt(r.get("hole_rate"), 5), fmt(r.get("dist_p99_rel_h"), 5), passes(r, "water.")] for r in m["rows"]])
    b = load("beams-1080p.json")
    table(out, "Beams (closed form)", b["commands"], b["not_finished"],
          ["beams", "size", "frames", "frame ms p50", "p95", "last beams.integrate GPU ms", "pairs", "culled"],
          [[str(r["beams"]), "%dx%d" % (r["width"], r["height"]), str(r["frames"]), fmt(r["frame_ms"]["p50"]),
            fmt(r["frame_ms"]["p95"]), fmt(r.get("last_gpu_ms")), str(r.get("pairs")), str(r.get("pairs_culled"))]
           for r in b["rows"]])
    s = load("default-scene-1080p.json")
    table(out, "Default scene (water, beams, volume, meshes)", s["commands"], s["not_finished"],
          ["size", "frames", "frame ms p50", "p95", "p99", "fps", "ms per pass"],
          [["%dx%d" % (r["width"], r["height"]), str(r["frames"]), fmt(r["frame_ms"]["p50"]), fmt(r["frame_ms"]["p95"]),
            fmt(r["frame_ms"]["p99"]), fmt(r.get("mean_fps"), 1), passes(r, "")] for r in s["rows"]])
    if os.path.exists(os.path.join(d, "sim-device.json")):
        v = load("sim-device.json")
        table(out, "Fluid solver (PBF) on the CPU and the GPU, the same dam-break block", v["commands"],
              v["not_finished"], ["particles", "iterations", "CPU threads", "CPU Mparticle-steps/s",
                                  "GPU Mparticle-steps/s", "GPU / CPU wall (median frame)"],
              [[str(r["particles"]), str(r["iterations"]), str(r["threads"]),
                fmt(r["cpu"]["particle_steps_per_s"] / 1e6), fmt(r["gpu"]["particle_steps_per_s"] / 1e6),
                fmt(r["gpu_wall_over_cpu_median"], 3)] for r in v["rows"]])
    if os.path.exists(os.path.join(d, "sim-water-1m-1080p.json")):
        f = load("sim-water-1m-1080p.json")
        table(out, "Simulation on the GPU and water in one frame", f["commands"], f["not_finished"],
              ["particles", "size", "frames", "frame ms p50", "p95", "sim device", "sim CPU ms p50", "ms per pass"],
              [[str(r.get("sim", {}).get("particles")), "%dx%d" % (r["width"], r["height"]), str(r["frames"]),
                fmt(r["frame_ms"]["p50"]), fmt(r["frame_ms"]["p95"]), str(r.get("sim", {}).get("device")),
                fmt(r.get("sim", {}).get("cpu_ms_p50")), passes(r, "water.")] for r in f["rows"]])
    print("\n".join(out))


main()
