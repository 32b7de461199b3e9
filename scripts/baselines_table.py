#!/usr/bin/env python3
"""HOT against the tuned algebraic baselines at equal cores (issue 20).

    python3 scripts/baselines_table.py results/baselines > results/baselines/tables.md
    python3 scripts/baselines_table.py results/baselines-repeat > results/baselines-repeat/spread.md
    python3 scripts/baselines_table.py results/petsc-baselines > results/petsc-baselines/tables.md

From a finished experiments/matrices/baselines.json run: seconds per timed
frame of every solver per scene and thread count, then HOT's lead over the
fastest algebraic multigrid (BoomerAMG or ML, with PN or L-BFGS) and over
the fastest of everything else, then per cell the outer and linear
iterations, the share of the timed steps spent in the setup and the last
hierarchy's operator complexity. Cells that did not converge or ran on a
busy machine are marked and not compared. A run with repeats gets the
spread table instead (spread(): two solvers; repeated(): more, every
number from the medians of the runs).
"""
import math
import os
import sys

from setting_table import counters, read_csv, setup_share, share

ALGEBRAIC = ("pn-amg-pcg", "lbfgs-amg", "pn-ml-pcg", "lbfgs-ml", "pn-gamg-pcg", "lbfgs-gamg")


def algebraic(solver):
    """An algebraic multigrid: a tuned preset, or PETSc's hypre, ML or GAMG by pc_type."""
    return solver.split(":")[0] in ALGEBRAIC or any(f":petsc:pc_type={p}" in solver for p in ("hypre", "ml", "gamg"))


def print_leads(leads, claim):
    """Per thread count ({threads: [ratios over scenes]}): `claim` with its
    geometric mean g, then the count and range of the scenes."""
    for t, v in leads.items():
        if v:
            g = math.exp(sum(math.log(x) for x in v) / len(v))
            print(f"\nAt {t} thread{'s' if t != '1' else ''}: " + claim.format(g=g) +
                  f" (geometric mean over {len(v)} scenes, {min(v):.2f}-{max(v):.2f}).")


def median(v):
    v = sorted(v)
    return v[len(v) // 2] if len(v) % 2 else (v[len(v) // 2 - 1] + v[len(v) // 2]) / 2


def repeated(d, cells):
    """For a run with repeats of more than two solvers: per scene and thread
    count, every solver's median s/frame over its runs with the spread
    ((max - min) / median), HOT's lead over each from the medians with the
    range over all pairs of runs, and the iterations, setup share and
    operator complexity of each solver's median run."""
    runs = {}
    for r in cells:
        runs.setdefault((r["scene"], r["threads"], r["solver"]), []).append(r)
    scenes = list(dict.fromkeys(r["scene"] for r in cells))
    solvers = list(dict.fromkeys(r["solver"] for r in cells))
    threads = sorted({r["threads"] for r in cells}, key=int, reverse=True)

    def times(key):
        return [float(r["s_per_frame"]) for r in runs.get(key, []) if good(r)]

    def median_run(key):
        ok = sorted((r for r in runs.get(key, []) if good(r)), key=lambda r: float(r["s_per_frame"]))
        return ok[(len(ok) - 1) // 2] if ok else (runs.get(key) or [None])[0]

    print("## Seconds per timed frame: median of the runs (spread)\n")
    print("Solvers: " + ", ".join(f"{chr(65 + i)} = `{so}`" for i, so in enumerate(solvers)) + "\n")
    print("| scene | threads | runs | " + " | ".join(chr(65 + i) for i in range(len(solvers))) + " |")
    print("|---|---:|---:|" + "---:|" * len(solvers))
    for sc in scenes:
        for t in threads:
            row, n = [], 0
            for so in solvers:
                v = times((sc, t, so))
                n = max(n, len(v))
                if v:
                    row.append(f"{median(v):.3g} ({(max(v) - min(v)) / median(v):.0%})")
                else:
                    r = median_run((sc, t, so))
                    why = (r["status"] if r["status"] != "ok" else r["worst_solve_status"]) if r else ""
                    row.append(f"- ({why})" if r else "")
            print(f"| {sc} | {t} | {n} | " + " | ".join(row) + " |")

    print("\n## Each solver's median s/frame over HOT's (range over all pairs of runs)\n")
    others = [so for so in solvers if so != "hot"]
    print("| scene | threads | " + " | ".join(chr(65 + solvers.index(so)) for so in others) + " |")
    print("|---|---:|" + "---:|" * len(others))
    leads = {t: [] for t in threads}
    for sc in scenes:
        for t in threads:
            h = times((sc, t, "hot"))
            if not h:
                continue
            row = []
            best = None
            for so in others:
                v = times((sc, t, so))
                if not v:
                    row.append("-")
                    continue
                pairs = [y / x for x in h for y in v]
                ratio = median(v) / median(h)
                row.append(f"{ratio:.2f} ({min(pairs):.2f}-{max(pairs):.2f})")
                if algebraic(so) and (best is None or ratio < best):
                    best = ratio
            if best is not None:
                leads[t].append(best)
            print(f"| {sc} | {t} | " + " | ".join(row) + " |")
    print_leads(leads, "the fastest algebraic multigrid of each scene takes {g:.2f}x HOT's median time")

    print("\n## Iterations, setup share, operator complexity (each solver's median run)\n")
    print("| scene | threads | solver | s/frame | outer | linear | inner | setup share | op. complexity | status |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---|")
    for sc in scenes:
        for t in threads:
            for so in solvers:
                r = median_run((sc, t, so))
                if not r:
                    continue
                st = r["worst_solve_status"] or r["status"]
                if r["status"] != "ok":
                    st = f"{r['status']} ({st} until then)"
                if r.get("machine_busy", "0") == "1":
                    st += " (machine busy)"
                sf = f"{float(r['s_per_frame']):.3g}" if good(r) else "-"
                print(f"| {sc} | {t} | {so} | {sf} | {r['outer_iters']} | "
                      f"{r['linear_iters']} | {r['inner_iters']} | {share(d, r)} | {op_complexity(d, r)} | {st} |")


def good(r):
    return r["status"] == "ok" and r["worst_solve_status"] == "converged" and r.get("machine_busy", "0") != "1"


def op_complexity(d, r):
    return counters(d, r)[1]


def spread(d):
    """For a run with repeats (matrix key "repeat"): per scene and thread
    count, each solver's median s/frame and the spread of its runs
    ((max - min) / median), and the ratio of the two solvers' medians with
    its range over all pairs of runs."""
    cells = [r for r in read_csv(os.path.join(d, "cells.csv")) if good(r)]
    runs = {}
    for r in cells:
        runs.setdefault((r["scene"], r["threads"]), {}).setdefault(r["solver"], []).append(float(r["s_per_frame"]))
    solvers = list(dict.fromkeys(r["solver"] for r in cells))
    a, b = solvers[0], solvers[-1]
    print(f"| scene | threads | runs | {a}: median s/frame (spread) | {b}: median s/frame (spread) |"
          f" {b} / {a}: median (range over run pairs) |")
    print("|---|---:|---:|---:|---:|---:|")
    for (sc, t), by in runs.items():
        if a not in by or b not in by:
            continue
        med = {k: sorted(v)[len(v) // 2] if len(v) % 2 else sum(sorted(v)[len(v) // 2 - 1:len(v) // 2 + 1]) / 2
               for k, v in by.items()}
        pairs = [y / x for x in by[a] for y in by[b]]
        print(f"| {sc} | {t} | {len(by[a])} | {med[a]:.3g} ({(max(by[a]) - min(by[a])) / med[a]:.0%}) | "
              f"{med[b]:.3g} ({(max(by[b]) - min(by[b])) / med[b]:.0%}) | {med[b] / med[a]:.2f} "
              f"({min(pairs):.2f}-{max(pairs):.2f}) |")


def main(d):
    cells = [r for r in read_csv(os.path.join(d, "cells.csv")) if r.get("role", "") != "reference"]
    if not cells:
        sys.exit(f"{d}/cells.csv: no cells")
    if any(r.get("repeat", "") not in ("", "1") for r in cells):
        if len({r["solver"] for r in cells}) > 2:
            repeated(d, cells)
        else:
            spread(d)
        return
    scenes = list(dict.fromkeys(r["scene"] for r in cells))
    solvers = list(dict.fromkeys(r["solver"] for r in cells))
    threads = sorted({r["threads"] for r in cells}, key=int, reverse=True)
    by = {(r["scene"], r["threads"], r["solver"]): r for r in cells}

    print("## Seconds per timed frame\n")
    print("| scene | threads | " + " | ".join(solvers) + " |")
    print("|---|---:|" + "---:|" * len(solvers))
    leads = {t: [] for t in threads}
    for sc in scenes:
        for t in threads:
            row = []
            for so in solvers:
                r = by.get((sc, t, so))
                if not r:
                    row.append("")
                    continue
                v = f"{float(r['s_per_frame']):.3g}" if r["s_per_frame"] else "-"
                row.append(v if good(r) else f"{v} ({r['worst_solve_status'] or r['status']})")
            print(f"| {sc} | {t} | " + " | ".join(row) + " |")

    print("\n## HOT's lead (s/frame of the other over HOT's)\n")
    print("| scene | threads | fastest algebraic | its s/frame over HOT's | fastest other (not HOT) | its s/frame over HOT's |")
    print("|---|---:|---|---:|---|---:|")
    for sc in scenes:
        for t in threads:
            hot = by.get((sc, t, "hot"))
            if not hot or not good(hot):
                continue
            h = float(hot["s_per_frame"])
            alg = [by[(sc, t, s)] for s in ALGEBRAIC if (sc, t, s) in by and good(by[(sc, t, s)])]
            oth = [by[(sc, t, s)] for s in solvers if s != "hot" and (sc, t, s) in by and good(by[(sc, t, s)])]
            a = min(alg, key=lambda r: float(r["s_per_frame"])) if alg else None
            o = min(oth, key=lambda r: float(r["s_per_frame"])) if oth else None
            if a:
                leads[t].append(float(a["s_per_frame"]) / h)
            print(f"| {sc} | {t} | {a['solver'] if a else '-'} | "
                  f"{float(a['s_per_frame']) / h:.2f} | " if a else f"| {sc} | {t} | - | - | ", end="")
            print(f"{o['solver']} | {float(o['s_per_frame']) / h:.2f} |" if o else "- | - |")
    print_leads(leads, "the fastest algebraic multigrid takes {g:.2f}x HOT's time")

    print("\n## Iterations, setup share, operator complexity\n")
    print("| scene | threads | solver | s/frame | outer | linear | setup share | op. complexity | status |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---|")
    for sc in scenes:
        for t in threads:
            for so in solvers:
                r = by.get((sc, t, so))
                if not r:
                    continue
                st = r["worst_solve_status"] or r["status"]
                if r.get("machine_busy", "0") == "1":
                    st += " (machine busy)"
                print(f"| {sc} | {t} | {so} | {float(r['s_per_frame'] or 'nan'):.3g} | {r['outer_iters']} | {r['linear_iters']} | "
                      f"{setup_share(d, r):.0%} | {op_complexity(d, r)} | {st} |")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
