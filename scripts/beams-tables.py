#!/usr/bin/python3
"""Markdown tables for docs/benchmarks-beams.md from the JSON lines of `volfx-bench beams`
(CPU, scripts/bench-beams.sh) or `volfx-bench beams --gpu`. usage: beams-tables.py cpu|gpu IN.jsonl
       beams-tables.py issue15 GPU15.jsonl PANEL.jsonl   (the issue 15 section)"""
import json
import sys

kind, path = sys.argv[1], sys.argv[2]
rows = [json.loads(l) for l in open(path) if l.strip() and not l.startswith("#")]


def issue15(rows, panel):
    """Table 4.2 with the new options (falloff, hot ramp, bloom) and the panel's passes."""
    print("| image | beams | falloff | bloom | method | integrate ms (p50) | x closed | bloom ms | max rel err | "
          "mean rel err | max err / (1e-5 + cond) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    closed = {}
    for r in rows:
        if "method" not in r or r.get("timing_only"):
            continue
        key = (r["width"], r["beams"], r["falloff"], r["bloom"])
        if r["method"] == "closed":
            closed[key] = r["gpu_ms_p50"]
        name = "closed form" if r["method"] == "closed" else f"march {r['samples']}"
        bloom = f"{r['bloom_ms']:.2f}" if r["bloom"] else "-"
        print(f"| {r['width']}x{r['height']} | {r['beams']} | {r['falloff']} | {'on' if r['bloom'] else 'off'} | {name} | "
              f"{r['gpu_ms_p50']:.2f} | {r['gpu_ms_p50'] / closed[key]:.2f} | {bloom} | {g(r['max_rel_err'])} | "
              f"{g(r['mean_rel_err'])} | {g(r['max_err_over_1e-5_plus_cond'])} |")
    # an animation row comes just before the method rows of its run: it takes their tags
    anim, pending = [], None
    for r in rows:
        if "animation" in r:
            pending = r
        elif "method" in r and pending is not None:
            anim.append((pending, r["falloff"], r["bloom"]))
            pending = None
    if anim:
        print()
        print("Cost under animation (changed against unchanged frames, frame ms p50; ratio near 1: "
              "animation costs nothing beyond drawing):")
        print()
        print("| image | beams | falloff | bloom | changed | unchanged | ratio |")
        print("|---|---|---|---|---|---|---|")
        for r, fo, bl in anim:
            a = r["animation"]
            print(f"| {r['width']}x{r['height']} | {r['beams']} | {fo} | {'on' if bl else 'off'} | "
                  f"{a['changed_frame_ms_p50']:.1f} | {a['unchanged_frame_ms_p50']:.1f} | {a['ratio']:.3f} |")
    print()
    print("Panel passes (GPU ms, median over the frames; `beams-panel.jsonl`):")
    print()
    print("| variant | integrate / march | bloom down | bloom up | composite |")
    print("|---|---|---|---|---|")
    for r in panel:
        if "png" not in r:
            continue
        im = r.get("integrate_ms", r.get("march_ms"))
        f = lambda k: f"{r[k]:.2f}" if k in r else "-"
        print(f"| {r['variant']} | {im:.1f} | {f('bloom_down_ms')} | {f('bloom_up_ms')} | {f('composite_ms')} |")
    eq = [r for r in panel if r.get("variant") == "equal-time"]
    an = [r for r in panel if r.get("variant") == "animation"]
    if eq:
        print()
        print(f"Equal time: ray marching with {eq[0]['samples']} samples comes nearest the closed form's integrate time "
              "on this scene (march probes in the JSON).")
    if an:
        print(f"Animated against frozen frames of the showcase: integrate {an[0]['animated_integrate_ms']:.0f} ms against "
              f"{an[0]['frozen_integrate_ms']:.0f} ms (ratio {an[0]['animated_integrate_ms'] / an[0]['frozen_integrate_ms']:.2f}).")




def g(x):
    return f"{x:.3g}"


if kind == "issue15":
    issue15(rows, [json.loads(l) for l in open(sys.argv[3]) if l.strip()])
    sys.exit(0)

if kind == "cpu":
    print("| image | beams | method | ms (p50) | x closed | max rel err | mean rel err | px > 1e-5 | max where cond < 1e-5 | max err / (1e-5 + cond) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    closed = {}
    for r in rows:
        key = (r["width"], r["beams"])
        if r["method"] == "closed_form":
            closed[key] = r["frame_ms"]["p50"]
        e = r["error_vs_f64_closed_form"]
        name = "closed form" if r["method"] == "closed_form" else f"march {r['samples']}"
        print(f"| {r['width']}^2 | {r['beams']} | {name} | {r['frame_ms']['p50']:.2f} | "
              f"{r['frame_ms']['p50'] / closed[key]:.2f} | {g(e['max_rel'])} | {g(e['mean_rel'])} | "
              f"{e['above_1e-5']} of {e['pixels']} | {g(e['max_rel_where_cond_below_1e-5'])} | "
              f"{g(e['max_err_over_1e-5_plus_cond'])} |")
elif kind == "gpu":
    table = [r for r in rows if "method" in r and not r.get("timing_only")]
    print("| beams | image | method | GPU ms | x closed | mean rel err | max rel err | px > 1e-5 | max where cond < 1e-5 | max err / (1e-5 + cond) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    closed = {}
    for r in table:
        key = (r["beams"], r["width"])
        if r["method"] == "closed":
            closed[key] = r["gpu_ms_p50"]
        name = "closed form" if r["method"] == "closed" else f"march {r['samples']}"
        print(f"| {r['beams']} | {r['width']}^2 | {name} | {r['gpu_ms_p50']:.2f} | {r['gpu_ms_p50'] / closed[key]:.2f} | "
              f"{g(r['mean_rel_err'])} | {g(r['max_rel_err'])} | {r['above_1e-5']} of {r['pixels']} | "
              f"{g(r['max_rel_where_cond_below_1e-5'])} | {g(r['max_err_over_1e-5_plus_cond'])} |")
    big = [r for r in rows if r.get("timing_only")]
    if big:
        print()
        print("| beams | image | frames | frame ms (p50) | last beams.integrate GPU ms | beam-tile pairs | culled |")
        print("|---|---|---|---|---|---|---|")
        for r in big:
            gms = "-" if r["last_gpu_ms"] is None else f"{r['last_gpu_ms']:.0f}"
            print(f"| {r['beams']} | {r['width']}x{r['height']} | {r['frames']} | {r['frame_ms_p50']:.0f} | "
                  f"{gms} | {r['pairs']:.0f} | {r['pairs_culled']:.0f} |")
    anim = [r for r in rows if "animation" in r]
    if anim:
        print()
        print("| beams | image | changed frame ms | unchanged frame ms | ratio |")
        print("|---|---|---|---|---|")
        for r in anim:
            a = r["animation"]
            print(f"| {r['beams']} | {r['width']}^2 | {a['changed_frame_ms_p50']:.2f} | {a['unchanged_frame_ms_p50']:.2f} | {a['ratio']:.3f} |")
elif kind == "summary":
    # one sentence per path: time ratio of marching with 120 samples to the closed form, and the
    # mean errors, so the prose of docs/benchmarks-beams.md is computed from this run's figures
    def ms(r):
        return r["frame_ms"]["p50"] if "frame_ms" in r else r["gpu_ms_p50"]

    def mean(r):
        return r["error_vs_f64_closed_form"]["mean_rel"] if "error_vs_f64_closed_form" in r else r["mean_rel_err"]

    def ratio(r):
        return r["error_vs_f64_closed_form"]["max_err_over_1e-5_plus_cond"] if "error_vs_f64_closed_form" in r \
            else r["max_err_over_1e-5_plus_cond"]

    rows = [r for r in rows if "method" in r and not r.get("timing_only")]
    closed = {(r["beams"], r["width"]): r for r in rows if r["method"] in ("closed", "closed_form")}
    m120 = [r for r in rows if r["samples"] == 120]
    m8 = [r for r in rows if r["samples"] == 8]
    x120 = [ms(r) / ms(closed[(r["beams"], r["width"])]) for r in m120]
    x8 = [ms(r) / ms(closed[(r["beams"], r["width"])]) for r in m8]
    cm = [mean(r) for r in closed.values()]
    print(f"marching with 120 samples takes {min(x120):.2f} to {max(x120):.2f}x the closed form's time "
          f"(8 samples: {min(x8):.2f} to {max(x8):.2f}x) with mean error {min(mean(r) for r in m120):.2g} to "
          f"{max(mean(r) for r in m120):.2g} against the closed form's {min(cm):.2g} to {max(cm):.2g}; "
          f"the closed form's largest error / (1e-5 H + cond) is {max(ratio(r) for r in closed.values()):.2f}")
