#!/usr/bin/python3
"""Plots `volfx-bench beams --gpu` JSON lines (or the CPU lines of scripts/bench-beams.sh): mean
relative error against ms per frame, one curve per (beams, size), closed form as a star.
usage: plot-beams-gpu.py IN.jsonl OUT.png"""
import json
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

rows = [json.loads(l) for l in open(sys.argv[1]) if l.strip() and not l.startswith("#")]
# CPU lines (scripts/bench-beams.sh) become the same shape as the GPU ones
cpu = any(r.get("device", "").startswith("cpu") for r in rows)
for r in rows:
    if r.get("device", "").startswith("cpu"):
        r["method"] = "closed" if r["method"] == "closed_form" else "march"
        r["gpu_ms_p50"] = r["frame_ms"]["p50"]
        r["mean_rel_err"] = r["error_vs_f64_closed_form"]["mean_rel"]
        r["gl_renderer"] = "CPU float32, 1 thread"
rows = [r for r in rows if "method" in r and not r.get("timing_only")]
fig, ax = plt.subplots(figsize=(7, 4.5))
groups = sorted({(r["beams"], r["width"]) for r in rows})
for g in groups:
    rs = [r for r in rows if (r["beams"], r["width"]) == g]
    march = sorted((r for r in rs if r["method"] == "march"), key=lambda r: r["samples"])
    line, = ax.plot([r["gpu_ms_p50"] for r in march], [r["mean_rel_err"] for r in march], "o-",
                    label=f"{g[0]} beams, {g[1]}^2: marching " + "/".join(str(r["samples"]) for r in march))
    closed = [r for r in rs if r["method"] == "closed"]
    ax.plot([r["gpu_ms_p50"] for r in closed], [r["mean_rel_err"] for r in closed], "*",
            markersize=14, color=line.get_color())
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xlabel(("ms per image" if cpu else "GPU ms per frame") + " (median, " + rows[0]["gl_renderer"] + ")")
ax.set_ylabel("mean relative error vs float64 closed form")
ax.set_title("Beams: closed form (stars) vs ray marching")
ax.legend(fontsize=7)
ax.grid(True, which="both", alpha=0.3)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)
