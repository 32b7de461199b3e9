#!/usr/bin/env python3
"""HOT's supplement Table 1 at the paper's particle counts, from a finished
matrix (experiments/matrices/paper-scale.json), beside the same solvers at
the benchmark scale (results/scenes-bench):

    python3 scripts/paper_scale_table.py results/paper-scale results/scenes-bench > results/paper-scale/table.md

Per scene: particles, seconds per timed frame of hot, pn-pcg-mf and pn-pcg,
HOT's speedup against each (one timed frame, so the total and the maximum
per-frame speedup of the paper's table are the same number), the outer and
linear iterations of the timed frame, peak resident memory (MB and KB per
particle), and HOT's speedup against pn-pcg at the benchmark scale. A cell
that did not end ok with every step converged shows '-'; one that ran while
the machine was busy is marked '(busy)' and left out of the summary.
"""
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from setting_table import ok, read_csv  # noqa: E402

SOLVERS = ["hot", "pn-pcg-mf", "pn-pcg"]
PAPER = {"pn-pcg": "1.98-5.79", "pn-pcg-mf": "1.05-5.76"}  # HOT paper section 6, total timing, 12 cores


def by_scene(d):
    cells = {}
    for r in read_csv(os.path.join(d, "cells.csv")):
        if r.get("role", "") != "reference":
            cells[(r["scene"], r["solver"])] = r
    return cells


def spf(r):
    return float(r["s_per_frame"]) if r and ok(r) else None


def busy(r):
    return bool(r) and r.get("machine_busy", "0") == "1"


def fmt(x, digits=3):
    return "-" if x is None else f"{x:.{digits}g}"


def geo(xs):
    return math.exp(sum(math.log(x) for x in xs) / len(xs)) if xs else None


def main(d, bench):
    cells, small = by_scene(d), by_scene(bench)
    scenes = list(dict.fromkeys(s for s, _ in cells))
    matrix = os.path.join(d, "matrix.json")
    if os.path.exists(matrix):  # the matrix's scene order, with the scenes not run yet
        with open(matrix) as f:
            scenes = json.load(f).get("matrix", {}).get("axes", {}).get("scene", scenes)
    rows, speed = [], {s: [] for s in SOLVERS[1:]}
    small_speed = []
    missing = []
    for sc in scenes:
        c = {s: cells.get((sc, s)) for s in SOLVERS}
        t = {s: spf(c[s]) for s in SOLVERS}
        if any(c[s] is None for s in SOLVERS):
            missing.append(sc)
        sp = {}
        for s in SOLVERS[1:]:
            sp[s] = t[s] / t["hot"] if t[s] and t["hot"] else None
            if sp[s] and not busy(c[s]) and not busy(c["hot"]):
                speed[s].append(sp[s])
        sh, sb = spf(small.get((sc, "hot"))), spf(small.get((sc, "pn-pcg")))
        ssp = sb / sh if sh and sb else None
        if ssp and sp["pn-pcg"] and not busy(c["pn-pcg"]) and not busy(c["hot"]):
            small_speed.append((sp["pn-pcg"], ssp))
        if all(c[s] is None for s in SOLVERS):
            continue
        parts = next((int(c[s]["particles"]) for s in SOLVERS if c[s]), 0)

        def cell(s):
            mark = " (busy)" if busy(c[s]) else ""
            return fmt(t[s]) + mark

        def iters(s):
            r = c[s]
            if not r or not ok(r):
                return "-"
            return r["outer_iters"] + (f" / {r['linear_iters']}" if s != "hot" else "")

        def mem(s):
            r = c[s]
            if not r or not r["peak_rss_mb"]:
                return "-"
            mb = float(r["peak_rss_mb"])
            return f"{mb:.0f} ({1024 * mb / parts:.1f})" if parts else f"{mb:.0f}"

        rows.append(f"| {sc} | {parts:,} | {cell('hot')} | {cell('pn-pcg-mf')} | {cell('pn-pcg')} | "
                    f"{fmt(sp['pn-pcg'])} | {fmt(sp['pn-pcg-mf'])} | {fmt(ssp)} | {iters('hot')} | "
                    f"{iters('pn-pcg-mf')} | {iters('pn-pcg')} | {mem('hot')} | {mem('pn-pcg-mf')} | {mem('pn-pcg')} |")

    print("# HOT supplement Table 1 at the paper's scale\n")
    for s in SOLVERS[1:]:
        g = geo(speed[s])
        if g:
            print(f"- HOT against {s}: {g:.2f}x as fast (geometric mean over {len(speed[s])} scenes, "
                  f"{min(speed[s]):.2f}-{max(speed[s]):.2f}x); the paper: {PAPER[s]}x on 12 cores.")
    if small_speed:
        ratio = geo([a / b for a, b in small_speed])
        print(f"- Against pn-pcg at the paper's scale HOT's lead is {ratio:.2f}x its lead at the benchmark scale "
              f"(~50k particles; geometric mean over {len(small_speed)} scenes).")
    if missing:
        print(f"- Not run yet: {', '.join(missing)} (some or all of the three solvers; `matrix run` resumes).")
    print("\nSeconds per timed frame (2 threads, scale 1, one timed frame; speedup = the solver's s/frame over "
          "HOT's; at ~50k: the same from results/scenes-bench, whose timed windows are longer), outer / linear "
          "iterations of the run, peak resident memory in MB (KB per particle):\n")
    print("| scene | particles | hot | pn-pcg-mf | pn-pcg | HOT vs pn-pcg | HOT vs pn-pcg-mf | HOT vs pn-pcg at ~50k | "
          "iters hot | iters pn-pcg-mf | iters pn-pcg | peak MB hot | peak MB pn-pcg-mf | peak MB pn-pcg |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(r)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit("usage: paper_scale_table.py RESULTS_DIR BENCH_RESULTS_DIR")
    main(sys.argv[1], sys.argv[2])
