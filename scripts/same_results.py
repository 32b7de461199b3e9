#!/usr/bin/env python3
"""Do two runs of one experiment matrix give the same results?

    scripts/same_results.py OLD_DIR NEW_DIR

OLD_DIR and NEW_DIR are `matrix run --out` folders (or two single `run --out`
folders). Cells are matched by id (the id is a hash of the cell's settings, so
the same matrix file gives the same ids); NEW_DIR may hold a subset of
OLD_DIR's cells (a run with --only). For every cell of NEW_DIR, every row of
steps.csv must agree on every column that is not a time: iterations, the
residual, the status, t and dt (printed to 17 digits, so the step length, which
the CFL rule takes from the particle velocities, checks the state bit for bit).
Prints one line per differing cell and a summary; exit 0 when all agree, 1 when
any differs or a cell of NEW_DIR is not in OLD_DIR, 2 on bad arguments.
"""
import csv
import os
import sys

# columns that measure time or the machine, not the result
SKIP = {"threads", "ref_s"}


def result_columns(header):
    return [c for c in header if not c.endswith("_s") and c not in SKIP]


def steps(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


def cell_dirs(top):
    cells = os.path.join(top, "cells")
    if os.path.isdir(cells):
        return {d: os.path.join(cells, d) for d in os.listdir(cells)
                if os.path.isfile(os.path.join(cells, d, "steps.csv"))}
    if os.path.isfile(os.path.join(top, "steps.csv")):
        return {".": top}
    return None


def compare(a_dir, b_dir):
    """None when the two steps.csv agree, else the first difference."""
    ha, ra = steps(os.path.join(a_dir, "steps.csv"))
    hb, rb = steps(os.path.join(b_dir, "steps.csv"))
    cols = result_columns(ha)
    missing = [c for c in cols if c not in hb]
    if missing:
        return "column %s missing" % missing[0]
    if len(ra) != len(rb):
        return "%d steps against %d" % (len(ra), len(rb))
    ia = {c: ha.index(c) for c in cols}
    ib = {c: hb.index(c) for c in cols}
    for k, (x, y) in enumerate(zip(ra, rb)):
        for c in cols:
            if x[ia[c]] != y[ib[c]]:
                return "step row %d, %s: %s against %s" % (k, c, x[ia[c]], y[ib[c]])
    return None


def main(argv):
    if len(argv) != 3:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    old, new = cell_dirs(argv[1]), cell_dirs(argv[2])
    for name, d in ((argv[1], old), (argv[2], new)):
        if d is None:
            print("same_results.py: %s: no cells/ and no steps.csv" % name, file=sys.stderr)
            return 2
    differ = 0
    for cid in sorted(new):
        if cid not in old:
            print("%s: not in %s" % (cid, argv[1]))
            differ += 1
            continue
        why = compare(old[cid], new[cid])
        if why:
            print("%s: %s" % (cid, why))
            differ += 1
    print("%d of %d cells give the same results (%d cells in %s)" % (len(new) - differ, len(new), len(old), argv[1]))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
