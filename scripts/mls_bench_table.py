#!/usr/bin/env python3
"""MLS-MPM against APIC from a finished mls-bench matrix (issue 21).

    python3 scripts/mls_bench_table.py results/mls-bench > results/mls-bench/mls-vs-apic.md

One row per scene and solver: seconds per timed frame and outer/linear
iterations with each transfer, the MLS/APIC time ratio, and each cell's
trajectory error at the last frame against the scene's APIC reference run
(pn-cholmod, eps 1e-10, dt sequence replayed): pos_rms and pos_max in dx,
vel_rms relative. For an APIC cell it is the solver's error at eps 1e-7;
for an MLS cell, the difference the transfer makes.
"""
import csv
import json
import os
import sys


def last_frame(d, cid):
    with open(os.path.join(d, "cells", cid, "frames.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    return rows[-1] if rows else {}


def transfer(r):
    s = r.get("set", "")
    return "mls" if "transfer=mls" in s else "apic"


def main(d):
    with open(os.path.join(d, "cells.csv"), newline="") as f:
        cells = [r for r in csv.DictReader(f) if r.get("role", "") != "reference"]
    by = {}
    for r in cells:
        by[(r["scene"], r["solver"], transfer(r))] = r
    scenes = list(dict.fromkeys(r["scene"] for r in cells))
    solvers = list(dict.fromkeys(r["solver"] for r in cells))
    print("| scene | solver | s/frame APIC | s/frame MLS | MLS/APIC time | outer (linear) APIC | outer (linear) MLS |"
          " APIC vs ref: pos_rms / pos_max [dx] | MLS vs APIC ref: pos_rms / pos_max [dx] | MLS vel_rms |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for sc in scenes:
        for so in solvers:
            a, m = by.get((sc, so, "apic")), by.get((sc, so, "mls"))
            if not a or not m:
                continue
            def cell(r):
                if r["status"] != "ok":
                    return r["status"], "-", "-"
                fr = last_frame(d, r["id"])
                return (float(r["s_per_frame"]), f"{r['outer_iters']} ({r['linear_iters']})",
                        f"{float(fr['pos_rms']):.2e} / {float(fr['pos_max']):.2e}", f"{float(fr['vel_rms']):.2e}")
            ca, cm = cell(a), cell(m)
            ok = a["status"] == "ok" and m["status"] == "ok"
            ratio = f"{ca[0] and cm[0] / ca[0]:.2f}" if ok else "-"
            fmt = lambda v: f"{v:.3f}" if isinstance(v, float) else v
            print(f"| {sc} | {so} | {fmt(ca[0])} | {fmt(cm[0])} | {ratio} | {ca[1]} | {cm[1]} | "
                  f"{ca[2] if ok or a['status'] == 'ok' else '-'} | {cm[2] if m['status'] == 'ok' else '-'} | "
                  f"{cm[3] if m['status'] == 'ok' else '-'} |")


if __name__ == "__main__":
    main(sys.argv[1])
