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
was busy are marked and left out of the means. A run with repeats gets
medians and the adoption rule instead (repeated()).
"""
import csv
import math
import os
import sys


# the algebraic presets the out-of-sample tuning (results/algebraic-tuning)
# sets, and the adapter spec its cells ran for each: a preset is its spec
# plus the options of the setting adopted there
TUNED_PRESETS = {"pn-amg-pcg": "pn:boomeramg:reuse_every=0", "lbfgs-amg": "lbfgs:boomeramg",
                 "pn-ml-pcg": "pn:ml:reuse_every=0", "lbfgs-ml": "lbfgs:ml"}


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


def share(d, r):
    """setup_share as text; '-' when the cell's steps.csv is not there"""
    x = setup_share(d, r)
    return "-" if x != x else f"{x:.0%}"


def median(v):
    v = sorted(v)
    return v[len(v) // 2] if len(v) % 2 else (v[len(v) // 2 - 1] + v[len(v) // 2]) / 2


def quiet_ok(r):
    return ok(r) and r.get("machine_busy", "0") != "1"


def medians(cells, axis):
    """Per (scene, solver, threads, setting): its runs; per (scene, solver,
    setting): the median s/frame of the converged runs on a quiet machine
    (NaN when any run failed) and whether a run failed; per solver the
    settings it ran in the matrix's order (each solver is judged against
    the first setting it ran: a matrix may pair settings with solvers by
    exclude rules, one library's options with its own solvers)."""
    settings = list(dict.fromkeys(r[axis] for r in cells))
    solvers = list(dict.fromkeys(r["solver"] for r in cells))
    runs, med, failed = {}, {}, {}
    for r in cells:
        runs.setdefault((r["scene"], r["solver"], r["threads"], r[axis]), []).append(r)
    for (scene, solver, _, setting), rows in runs.items():
        bad = any(not ok(r) for r in rows)
        t = [float(r["s_per_frame"]) for r in rows if quiet_ok(r)]
        failed[(scene, solver, setting)] = bad
        med[(scene, solver, setting)] = median(t) if t and not bad else float("nan")
    own = {sv: [st for st in settings if any(r["solver"] == sv and r[axis] == st for r in cells)] for sv in solvers}
    return runs, med, failed, own


def adoption(cells, axis):
    """The adoption rule of the tuning matrices (written in their
    descriptions), per solver: a setting beats the solver's first one when it
    converged in every run of every scene and its median is lower on every
    scene where the first converged (a scene the first failed counts as a
    win); of the winners, the lowest geometric mean of the ratios.
    {solver: {"first": setting, "judged": [(setting, converged, faster,
    geo_mean, wins)], "best": (setting, geo_mean) or None}}"""
    scenes = list(dict.fromkeys(r["scene"] for r in cells))
    _, med, failed, own = medians(cells, axis)
    out = {}
    for solver, mine in own.items():
        first, judged, best = mine[0], [], None
        for setting in mine[1:]:
            conv = all(not failed.get((sc, solver, setting), True) for sc in scenes)
            ratios, faster = [], conv
            for sc in scenes:
                a, b = med.get((sc, solver, setting), float("nan")), med.get((sc, solver, first), float("nan"))
                if b == b and a == a:
                    ratios.append(a / b)
                    faster = faster and a < b
            g = math.exp(sum(math.log(x) for x in ratios) / len(ratios)) if ratios else float("nan")
            wins = conv and faster
            if wins and (best is None or g < best[1]):
                best = (setting, g)
            judged.append((setting, conv, faster, g, wins))
        out[solver] = {"first": first, "judged": judged, "best": best}
    return out


def repeated(d, cells, axis):
    """A tuning run with repeats: per scene and solver form, each setting's
    median s/frame over its converged runs on a quiet machine, the spread,
    the ratio to the solver's first setting's median, the iterations of the
    median run; then the adoption rule (adoption())."""
    settings = list(dict.fromkeys(r[axis] for r in cells))
    scenes = list(dict.fromkeys(r["scene"] for r in cells))
    solvers = list(dict.fromkeys(r["solver"] for r in cells))
    runs, med, failed, own = medians(cells, axis)
    print(f"| scene | solver | threads | {axis} | runs | s/frame: median (spread) | / first | outer | linear |"
          " setup share | op. complexity | status |")
    print("|---|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|")
    for (scene, solver, threads, setting), rows in sorted(
            runs.items(), key=lambda kv: (scenes.index(kv[0][0]), solvers.index(kv[0][1]), kv[0][2],
                                          settings.index(kv[0][3]))):
        good = sorted((r for r in rows if quiet_ok(r)), key=lambda r: float(r["s_per_frame"]))
        bad = failed[(scene, solver, setting)]
        r = good[(len(good) - 1) // 2] if good else rows[0]
        t = [float(x["s_per_frame"]) for x in good]
        m = med[(scene, solver, setting)]
        first = med.get((scene, solver, own[solver][0]), float("nan"))
        ratio = m / first if not bad and first == first and first > 0 else float("nan")
        status = "converged" if not bad else (r["worst_solve_status"] or r["status"])
        if not bad and not good:
            status = "no run on a quiet machine"
        if any(x.get("machine_busy", "0") == "1" for x in rows):
            status += " (a run on a busy machine, left out)"
        spread = f" ({(max(t) - min(t)) / m:.0%})" if t and m == m else ""
        print(f"| {scene} | {solver} | {threads} | {setting} | {len(rows)} | "
              f"{'-' if m != m else f'{m:.3g}{spread}'} | {'-' if ratio != ratio else f'{ratio:.2f}'} | "
              f"{r['outer_iters']} | {r['linear_iters']} | {share(d, r)} | {counters(d, r)[1]} | {status} |")
    print()
    print("Adoption rule (a setting wins when it converged on every scene and its median is below the first "
          f"{axis}'s on every scene the first converged on):")
    print()
    for solver, a in adoption(cells, axis).items():
        print(f"| solver | {axis} | converged on every scene | faster on every scene | geo. mean of the ratios | wins |")
        print("|---|---|---|---|---:|---|")
        for setting, conv, faster, g, wins in a["judged"]:
            print(f"| {solver} | {setting} | {'yes' if conv else 'no'} | {'yes' if faster else 'no'} | "
                  f"{'-' if g != g else f'{g:.2f}'} | {'yes' if wins else 'no'} |")
        best = a["best"]
        print()
        print(f"{solver}: " + (f"adopt {axis} {best[0]} (geometric mean {best[1]:.2f} of the first's time)."
                               if best else f"keep the first {axis} ({a['first']})."))
        print()


def main(d, axis):
    cells = [r for r in read_csv(os.path.join(d, "cells.csv")) if r.get("role", "") != "reference"]
    if not cells:
        sys.exit(f"{d}/cells.csv: no cells")
    if axis not in cells[0]:
        sys.exit(f"{d}/cells.csv: no column '{axis}' (the matrix's solver_opts axis name)")
    if any(r.get("repeat", "") not in ("", "1") for r in cells):
        repeated(d, cells, axis)
        return
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
