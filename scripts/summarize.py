#!/usr/bin/env python3
"""Summary table of mpmbench runs, with times relative to a baseline solver.

usage: scripts/summarize.py [--baseline NAME] [--focus NAME] [--csv FILE]
                            [--from-frame [SCENE=]N ...] [--no-markdown] RUN_DIR ...

Each RUN_DIR is the --out directory of one `mpmbench run` (frames.csv and
run.json); a directory without frames.csv is searched recursively for run
directories, so `summarize.py results/stiffness` takes the whole sweep.

Runs are grouped into cases by (scene, scale, eps, --set overrides); within a
case there is one row per solver with the totals over the run's frames:
frames done / asked, steps, outer (nonlinear) and linear iterations, wall
seconds (sum of frames.csv wall_s), seconds per frame, the largest final
residual, the worst status (converged < capped < stalled < failed; a run with
fewer frames than asked is marked incomplete), and the time ratio to the
baseline solver of the same case (s/frame over the baseline's s/frame, so
runs cut short still compare) with its inverse, the speedup over the
baseline.

--from-frame N counts only frames N, N+1, ... (0-based, as in frames.csv) of
every run, SCENE=N only those of that scene's runs: a benchmark whose action
starts late (a pusher reaching its target) is timed over the frames that
have it; the frames column then shows the window.

Prints a Markdown table (and, when the --focus solver is present, default
"hot", a small table of its speedup over the baseline per case); --csv also
writes every row as CSV. Python 3 standard library only.

Exit status: 0, or 2 for bad arguments or when no run is found.
"""
import argparse
import csv
import json
import math
import os
import sys

STATUS_RANK = {"converged": 0, "capped": 1, "stalled": 2, "failed": 3}


def find_runs(paths):
    runs = []
    for p in paths:
        if os.path.isfile(os.path.join(p, "frames.csv")):
            runs.append(p)
            continue
        if not os.path.isdir(p):
            print(f"summarize: warning: {p}: not a directory, skipped", file=sys.stderr)
            continue
        found = []
        for dirpath, dirnames, filenames in os.walk(p):
            dirnames.sort()
            if "frames.csv" in filenames:
                found.append(dirpath)
        if not found:
            print(f"summarize: warning: {p}: no frames.csv found", file=sys.stderr)
        runs.extend(found)
    return runs


def number(s, default=float("nan")):
    try:
        return float(s)
    except (TypeError, ValueError):
        return default


def load_run(d, from_frame=0):
    meta = {}
    try:
        with open(os.path.join(d, "run.json")) as f:
            meta = json.load(f)
    except (OSError, ValueError) as e:
        print(f"summarize: warning: {d}/run.json: {e}; using frames.csv only", file=sys.stderr)
    with open(os.path.join(d, "frames.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    frames_done = len(rows)
    if from_frame:
        rows = [x for x in rows if int(number(x["frame"], -1)) >= from_frame]
    r = {
        "dir": d,
        "scene": meta.get("scene") or (rows[0]["scene"] if rows else "?"),
        "solver": meta.get("solver") or (rows[0]["solver"] if rows else os.path.basename(d.rstrip("/"))),
        "scale": number(meta.get("scale"), 1.0),
        "eps": number(meta.get("eps")),
        "overrides": {str(k): str(v) for k, v in (meta.get("overrides") or {}).items()},
        "frames_asked": int(meta["frames"]) if "frames" in meta else None,
        "threads": meta.get("threads", rows[0].get("threads") if rows else ""),
        "particles": meta.get("particles", ""),
        "frames": len(rows),
        "from_frame": from_frame,
        "frames_done": frames_done,
        "steps": sum(int(number(x["steps"], 0)) for x in rows),
        "outer": sum(int(number(x["outer_iters"], 0)) for x in rows),
        "linear": sum(int(number(x["linear_iters"], 0)) for x in rows),
        "wall": sum(number(x["wall_s"], 0.0) for x in rows),
        "max_residual": max((number(x["max_residual"]) for x in rows), default=float("nan")),
    }
    worst = "converged" if rows else "none"
    for x in rows:
        if STATUS_RANK.get(x["status"], 9) > STATUS_RANK.get(worst, -1):
            worst = x["status"]
    r["status"] = worst
    r["complete"] = r["frames_asked"] is None or frames_done >= r["frames_asked"]
    r["s_per_frame"] = r["wall"] / r["frames"] if r["frames"] else float("nan")
    return r


def sort_value(v):
    x = number(v)
    return (0, x, "") if math.isfinite(x) else (1, 0.0, v)


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    if isinstance(x, int):
        return str(x)
    a = abs(x)
    if a >= 10 ** digits:
        return f"{x:.0f}"
    if a == 0:
        return "0"
    if a < 1e-3:
        return f"{x:.{digits - 1}e}"
    decimals = max(0, digits - 1 - int(math.floor(math.log10(a))))
    return f"{x:.{decimals}f}"


def markdown(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", metavar="RUN_DIR")
    ap.add_argument("--baseline", default="pn-pcg", help="solver the time ratios refer to (default pn-pcg)")
    ap.add_argument("--focus", default="hot", help="solver whose speedup gets its own table (default hot)")
    ap.add_argument("--csv", help="also write the rows to this CSV file")
    ap.add_argument("--no-markdown", action="store_true", help="print nothing (with --csv)")
    ap.add_argument("--from-frame", action="append", default=[], metavar="[SCENE=]N",
                    help="count only frames >= N (of SCENE's runs); repeatable")
    a = ap.parse_args(argv)
    windows = {}
    for w in a.from_frame:
        scene, _, n = w.rpartition("=")
        try:
            windows[scene] = int(n)
        except ValueError:
            print(f"summarize: --from-frame {w}: expected [SCENE=]N with N an integer", file=sys.stderr)
            return 2
        if windows[scene] < 0:
            print(f"summarize: --from-frame {w}: expected N >= 0", file=sys.stderr)
            return 2

    dirs = find_runs(a.runs)
    if not dirs:
        print("summarize: no run directories (with frames.csv) found", file=sys.stderr)
        return 2
    runs = []
    for d in dirs:
        r = load_run(d)
        start = windows.get(r["scene"], windows.get("", 0))
        runs.append(load_run(d, start) if start else r)

    # cases and solver order (first appearance)
    keys = sorted({k for r in runs for k in r["overrides"]})
    solvers = []
    for r in runs:
        if r["solver"] not in solvers:
            solvers.append(r["solver"])

    def case_of(r):
        return (r["scene"], r["scale"], r["eps"], tuple(r["overrides"].get(k, "") for k in keys))

    def case_sort(c):
        return (c[0], c[1], c[2] if math.isfinite(c[2]) else 0.0, tuple(sort_value(v) for v in c[3]))

    cases = {}
    for r in runs:
        c = cases.setdefault(case_of(r), {})
        old = c.get(r["solver"])
        if old is not None:
            keep = r if r["frames"] > old["frames"] else old
            print(f"summarize: warning: two runs of {r['solver']} for the same case ({old['dir']}, {r['dir']}); "
                  f"keeping {keep['dir']}", file=sys.stderr)
            r = keep
        c[r["solver"]] = r

    if a.baseline not in solvers:
        print(f"summarize: warning: no run of the baseline solver '{a.baseline}': no time ratios", file=sys.stderr)
    scales = {c[1] for c in cases}
    epss = {c[2] for c in cases}
    base = a.baseline
    table, csv_rows = [], []
    for case in sorted(cases, key=case_sort):
        by_solver = cases[case]
        b = by_solver.get(base)
        for s in solvers:
            r = by_solver.get(s)
            if r is None:
                continue
            ratio = speedup = float("nan")
            if b is not None and b["s_per_frame"] > 0 and r["s_per_frame"] > 0:
                ratio = r["s_per_frame"] / b["s_per_frame"]
                speedup = 1.0 / ratio
            frames = f"{r['frames']}" if r["frames_asked"] is None else f"{r['frames_done']}/{r['frames_asked']}"
            if r["from_frame"]:
                frames = f"{r['from_frame']}-{r['frames_done'] - 1} of {frames}"
            status = r["status"] if r["complete"] else f"incomplete ({r['status']})"
            row = [case[0]] + list(case[3])
            if len(scales) > 1:
                row.append(fmt(case[1]))
            if len(epss) > 1:
                row.append(f"{case[2]:.0e}")
            row += [s, frames, r["steps"], r["outer"], r["linear"], fmt(r["wall"]), fmt(r["s_per_frame"]),
                    status, fmt(ratio), fmt(speedup)]
            table.append(row)
            csv_rows.append({
                "scene": case[0], "scale": case[1], "eps": case[2],
                "overrides": ";".join(f"{k}={v}" for k, v in zip(keys, case[3]) if v != ""),
                **{k: v for k, v in zip(keys, case[3])},
                "solver": s, "frames_done": r["frames_done"], "from_frame": r["from_frame"],
                "frames_timed": r["frames"],
                "frames_asked": "" if r["frames_asked"] is None else r["frames_asked"],
                "steps": r["steps"], "outer_iters": r["outer"], "linear_iters": r["linear"],
                "wall_s": f"{r['wall']:.6f}", "s_per_frame": f"{r['s_per_frame']:.6f}",
                "max_residual": f"{r['max_residual']:.6e}", "worst_status": r["status"],
                "complete": int(r["complete"]),
                f"ratio_to_{base}": "" if not math.isfinite(ratio) else f"{ratio:.6f}",
                f"speedup_vs_{base}": "" if not math.isfinite(speedup) else f"{speedup:.6f}",
                "threads": r["threads"], "particles": r["particles"], "run_dir": r["dir"],
            })

    if a.csv:
        fields = (["scene", "scale", "eps", "overrides"] + keys +
                  ["solver", "frames_done", "from_frame", "frames_timed", "frames_asked", "steps", "outer_iters", "linear_iters", "wall_s",
                   "s_per_frame", "max_residual", "worst_status", "complete", f"ratio_to_{base}",
                   f"speedup_vs_{base}", "threads", "particles", "run_dir"])
        try:
            d = os.path.dirname(a.csv)
            if d:
                os.makedirs(d, exist_ok=True)
            with open(a.csv, "w", newline="") as f:
                w = csv.DictWriter(f, fieldnames=fields, lineterminator="\n")
                w.writeheader()
                w.writerows(csv_rows)
        except OSError as e:
            print(f"summarize: {a.csv}: {e}", file=sys.stderr)
            return 2

    if a.no_markdown:
        return 0
    header = ["scene"] + keys
    if len(scales) > 1:
        header.append("scale")
    if len(epss) > 1:
        header.append("eps")
    header += ["solver", "frames", "steps", "outer", "linear", "wall s", "s/frame", "worst status",
               f"time/{base}", f"speedup vs {base}"]
    print(markdown(header, table))
    threads = sorted({str(r["threads"]) for r in runs})
    print(f"\n{len(runs)} runs; threads: {', '.join(threads)}; time ratios use s/frame of the same case "
          f"(speedup > 1: faster than {base}).")

    focus = a.focus
    if focus and focus != base and focus in solvers and base in solvers:
        rows = []
        for case in sorted(cases, key=case_sort):
            f, b = cases[case].get(focus), cases[case].get(base)
            if f is None or b is None or not (f["s_per_frame"] > 0):
                continue
            label = ", ".join(f"{k}={v}" for k, v in zip(keys, case[3]) if v != "") or "-"
            rows.append([case[0], label, fmt(b["s_per_frame"]), fmt(f["s_per_frame"]),
                         fmt(b["s_per_frame"] / f["s_per_frame"]),
                         fmt((b["outer"] / b["frames"]) / (f["outer"] / f["frames"]) if f["outer"] else float("nan"))])
        if rows:
            print(f"\n{focus} vs {base}:\n")
            print(markdown(["scene", "case", f"{base} s/frame", f"{focus} s/frame", "speedup",
                            f"outer iterations/frame, {base} over {focus}"], rows))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
