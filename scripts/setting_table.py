#!/usr/bin/env python3
"""Settings compared side by side from a finished matrix (tuning and reuse).

    python3 scripts/setting_table.py results/amg-tuning variant > results/amg-tuning/settings.md

AXIS is the matrix's named solver_opts axis (a column of cells.csv). One
row per cell, grouped by scene, solver and threads: seconds per timed
frame, its ratio to the group's first setting (the default), outer and
linear iterations, the share of the timed steps spent in the inverse
approximation's setup (steps.csv setup_s over wall_s), the setup counters
and the last hierarchy's operator complexity (inverse_stats.csv) and the
status. Then, per setting, the geometric mean
of the ratio over the groups where every setting ended converged, so a
setting is judged on all scenes at once. Cells that ran while the machine
was busy are marked and left out of the means.
"""
import csv
import math
import os
import sys


def read_csv(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def setup_share(d, r):
    steps = read_csv(os.path.join(d, "cells", r["id"], "steps.csv"))
    first = int(r.get("first_timed_frame") or 0)
    wall = sum(float(s["wall_s"]) for s in steps if int(s["frame"]) >= first)
    setup = sum(float(s["setup_s"] or 0) for s in steps if int(s["frame"]) >= first)
    return setup / wall if wall > 0 else float("nan")


def counters(d, r):
    st = {row["key"]: row["value"] for row in read_csv(os.path.join(d, "cells", r["id"], "inverse_stats.csv"))}
    oc = st.get("operator_complexity")
    oc = f"{float(oc):.2f}" if oc else "-"
    if "rebuilds" not in st:
        return "-", oc
    return f"{st['rebuilds']} / {st.get('refreshes', '0')} / {st.get('lagged', '0')}", oc


def ok(r):
    return r["status"] == "ok" and r["worst_solve_status"] == "converged"


def main(d, axis):
    cells = [r for r in read_csv(os.path.join(d, "cells.csv")) if r.get("role", "") != "reference"]
    if not cells:
        sys.exit(f"{d}/cells.csv: no cells")
    if axis not in cells[0]:
        sys.exit(f"{d}/cells.csv: no column '{axis}' (the matrix's solver_opts axis name)")
    settings = list(dict.fromkeys(r[axis] for r in cells))
    groups = {}
    for r in cells:
        groups.setdefault((r["scene"], r["solver"], r["threads"]), []).append(r)
    print(f"| scene | solver | threads | {axis} | s/frame | / first | outer | linear | setup share |"
          " rebuilds / refreshes / lagged | op. complexity | status |")
    print("|---|---|---:|---|---:|---:|---:|---:|---:|---|---:|---|")
    ratios = {s: [] for s in settings}
    for (scene, solver, threads), rows in groups.items():
        rows.sort(key=lambda r: settings.index(r[axis]))
        base = rows[0]
        t0 = float(base["s_per_frame"]) if ok(base) else float("nan")
        complete = all(ok(r) and r.get("machine_busy", "0") != "1" for r in rows)
        for r in rows:
            t = float(r["s_per_frame"]) if r["s_per_frame"] else float("nan")
            ratio = t / t0 if ok(r) and t0 == t0 and t0 > 0 else float("nan")
            if complete and r is not base:
                ratios[r[axis]].append(ratio)
            status = r["status"] if r["status"] != "ok" else r["worst_solve_status"]
            if r.get("machine_busy", "0") == "1":
                status += " (machine busy: time not valid)"
            print(f"| {scene} | {solver} | {threads} | {r[axis]} | {t:.3g} | "
                  f"{'-' if ratio != ratio else f'{ratio:.2f}'} | {r['outer_iters']} | {r['linear_iters']} | "
                  f"{setup_share(d, r):.0%} | {' | '.join(counters(d, r))} | {status} |")
    print()
    print(f"Geometric mean of s/frame relative to the first {axis} over the groups where every setting"
          " converged on a quiet machine (below 1: faster):")
    print()
    print(f"| {axis} | groups | geo. mean | range |")
    print("|---|---:|---:|---|")
    for s in settings[1:]:
        v = [x for x in ratios[s] if x == x]
        if not v:
            print(f"| {s} | 0 | - | - |")
            continue
        g = math.exp(sum(math.log(x) for x in v) / len(v))
        print(f"| {s} | {len(v)} | {g:.2f} | {min(v):.2f}-{max(v):.2f} |")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
