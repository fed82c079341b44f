#!/usr/bin/env python3
"""tetvol-mpi-table.py RESULTS.jsonl — markdown tables from volfx-tetvol-mpi's JSON lines."""
import json
import sys

rows = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
for s in (r for r in rows if r["test"] == "setup"):
    print(f"- ranks {s['ranks']}: mesh {s['mesh']} ({s['tets']} tets, field {s['field']}), "
          f"{s['size']}x{s['size']}, view {s['view']}, cores {s['cores']}, threshold "
          f"{s['threshold']}, D {s['D']}, C {s['C']}, one process (threads=1) "
          f"{s['one_process_ms']:.0f} ms")
print()
print("| P | mode | median ms | vs base (same P) | scanned | skipped by ERT | imbalance T_sc max/mean "
      "| imbalance CPU max/mean | imbalance scanned | keys moved by DLB | swap bytes (sum) | max diff vs 1 process |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
base = {}
for r in (r for r in rows if r["test"] == "mode"):
    if r["mode"] == "base":
        base[r["ranks"]] = r["median_ms"]
    b = base.get(r["ranks"])
    ratio = f"{b / r['median_ms']:.2f}x" if b else "-"
    print(f"| {r['ranks']} | {r['mode']} | {r['median_ms']:.0f} | {ratio} | {r['cells_scanned']} | "
          f"{r['cells_skipped_ert']} | {r['imbalance_t_sc']:.2f} | {r['imbalance_cpu']:.2f} | "
          f"{r['imbalance_scanned']:.2f} | "
          f"{r['keys_moved']} | {r['swap_bytes']} | {r['max_vs_one_process']:.2g} |")
print()
print("Phases of the last render (max over ranks, ms): set-up (replicated) / phase 1 / export / "
      "binary swap (includes waiting for the partner) / gather")
print()
print("| P | mode | set-up | phase 1 | export | swap | gather |")
print("|---|---|---|---|---|---|---|")
for r in (r for r in rows if r["test"] == "mode"):
    print(f"| {r['ranks']} | {r['mode']} | {max(r['t_setup_ms']):.0f} | {max(r['t_phase1_ms']):.0f} | "
          f"{max(r['t_export_ms']):.0f} | {max(r['t_swap_ms']):.0f} | {max(r['t_gather_ms']):.0f} |")
print()
print("Per rank (last render of each configuration): scanned cells / segments made / segments "
      "after the scan / phase-1 CPU ms / T_sc wall ms / poll ms / idle ms / swap bytes sent")
print()
print("| P | mode | per rank |")
print("|---|---|---|")
for r in (r for r in rows if r["test"] == "mode"):
    per = "; ".join(
        f"{r['scanned'][i]}/{r['segments_made'][i]}/{r['segments_local'][i]}/"
        f"{r['t_phase1_cpu_ms'][i]:.0f}/{r['t_sc_ms'][i]:.0f}/{r['t_comm_ms'][i]:.0f}/"
        f"{r['t_idle_ms'][i]:.0f}/{r['swap_bytes_rank'][i]}"
        for i in range(r["ranks"]))
    print(f"| {r['ranks']} | {r['mode']} | {per} |")
print()
print("Phase-1 CPU time of the busiest rank (ms; what the slowest node would take with one core "
      "per rank; sum over ranks in brackets), last render:")
print()
modes = ["base", "dlb", "ert", "ert_share", "ert_dlb", "ert_share_dlb"]
print("| P | " + " | ".join(modes) + " |")
print("|---|" + "---|" * len(modes))
by = {}
for r in (r for r in rows if r["test"] == "mode"):
    by[(r["ranks"], r["mode"])] = r
for p in sorted({k[0] for k in by}):
    cells = []
    for m in modes:
        r = by.get((p, m))
        cells.append(f"{max(r['t_phase1_cpu_ms']):.0f} ({sum(r['t_phase1_cpu_ms']):.0f})" if r else "-")
    print(f"| {p} | " + " | ".join(cells) + " |")
