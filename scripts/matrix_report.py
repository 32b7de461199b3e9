#!/usr/bin/env python3
"""Report of an experiment-matrix run: `mpmbench matrix report DIR` runs this
with the python3 on PATH (or MPM_PYTHON), which needs matplotlib (Debian:
python3-matplotlib; or pip install matplotlib in a virtual environment).

usage: matrix_report.py DIR

DIR is the --out directory of `mpmbench matrix run` (cells.csv, matrix.json,
cells/<id>/frames.csv and, when present, iters.csv and mg_levels.csv; every
table is read by column name). Writes

  DIR/report.md        the tables below and links to the figures;
  DIR/report.csv       one row per (case, solver) of the tables;
  DIR/profile.csv      the performance-profile ratios (case, solver, ratio);
  DIR/figures/*.png    800 x 500 pixels each.

A case is one combination of every cell column but the solver (scene, eps,
scale, threads, frames, timed window, named axes but "solver_setting", which
holds per-solver settings such as a CFL number). An overview gives every
case's s/frame per solver and the speedups against the baseline (total /
max per frame, HOT Fig. 15); then, per case, a table of
solvers (HOT supplement Table 1): seconds per frame over the timed window,
the total speedup against the matrix's baseline solver (its timed wall time
over the solver's) and the largest per-frame speedup (max over the timed
frames of the baseline's frame time over the solver's), outer and linear
iterations over the window (and linear per step, HOT Table 3), and the worst
status (the cell's status when it did not end "ok", else the worst solve
status of its frames), the smallest and the average time step over the
window (steps.csv dt; Gast et al. 2015 Fig. 18) and the largest CN residual
of its frames. Speedups need both cells to have ended ok.

Figures: Dolan-More performance profiles over all cases (the fraction of
cases in which a solver's s/frame is within a factor tau of the best one; a
cell that did not end ok with every step converged counts as never within);
frame time per solver for every case with more than one frame (HOT Fig. 11);
s/frame and iterations against the modulus when a named set axis sets a
Young's modulus (a key ending in ".E"; HOT Fig. 20); residual against time
and against iterations for the cells run with history (first step of the
first timed frame, HOT Figs. 16/17). With report.mg_levels in the matrix,
also blocks per row per multigrid level (HOT Fig. 8) from mg_levels.csv.

Accuracy (matrix_report_accuracy.py, beside this file): for cells run with
error_ref or against a reference run, work-precision diagrams (wall time
against the median per-step err_h and against the last frame's pos_rms, one
PNG per case without eps, one line per solver), the time to reach err_h <=
1e-2 / 1e-3 / 1e-4 / 1e-6 interpolated along eps, performance profiles at matched
accuracy and wp.csv; with DIR/check.csv (matrix run --check) the case x
solver pass/fail grid. Reference-run cells (cells.csv role "reference") are
listed on their own, not as solvers of the cases.

Exit status: 0, 2 for a directory without cells.csv/matrix.json, 1 when
matplotlib is missing.
"""
import csv
import json
import math
import os
import re
import sys

FIG_W, FIG_H, DPI = 8.0, 5.0, 100  # 800 x 500 pixels
STATUS_RANK = {"converged": 0, "capped": 1, "stalled": 2, "timeout": 3, "failed": 4}
CASE_SKIP = {"id", "solver", "set", "solver_opts", "role", "reference"}  # not part of a case key
SMALL_COLUMNS = {"min_dt", "avg_dt", "max_residual"}  # written as %e in report.csv
# A named axis called "solver_setting" holds settings that belong to a solver
# rather than to the case (paired with solvers by include/exclude rules, e.g.
# the semi-implicit method's own CFL number in gast15-fig18.json): it is not
# part of the case key, so those cells are compared with the others.
SOLVER_AXES = {"solver_setting"}


def ranks_text(invocation):
    """', mpirun: K ranks x J jobs' for a distributed run (provenance 'ranks' > 1), else ''."""
    ranks, jobs = invocation.get("ranks", 1), invocation.get("jobs_per_rank", 1)
    if not isinstance(ranks, int) or ranks <= 1:
        return ""
    return f", mpirun: {ranks} ranks x {jobs} job{'s' if jobs != 1 else ''}"


def die(msg, code=2):
    print(f"matrix report: {msg}", file=sys.stderr)
    sys.exit(code)


def number(s, default=float("nan")):
    try:
        return float(s)
    except (TypeError, ValueError):
        return default


def read_csv(path):
    try:
        with open(path, newline="") as f:
            return list(csv.DictReader(f))
    except OSError:
        return None


def fmt(x, digits=3):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "-"
    if isinstance(x, int):
        return f"{x:,}"
    a = abs(x)
    if a == 0:
        return "0"
    if a >= 10 ** digits:
        return f"{x:,.0f}"
    if a < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{max(0, digits - 1 - int(math.floor(math.log10(a))))}f}"


def markdown(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def slug(text):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)[:60]


class Cell:
    """One cells.csv row and what its directory holds over the timed window."""

    def __init__(self, row, root):
        self.row = row
        self.id = row["id"]
        self.solver = row.get("solver", "?")
        self.first = int(number(row.get("first_timed_frame"), 0))
        self.status = row.get("status", "")
        d = os.path.join(root, "cells", self.id)
        self.dir = d
        frames = read_csv(os.path.join(d, "frames.csv")) or []
        self.frame_time = {}  # frame -> wall_s, every frame
        self.outer = self.linear = self.steps = 0
        for f in frames:
            k = int(number(f.get("frame"), -1))
            self.frame_time[k] = number(f.get("wall_s"), 0.0)
            if k >= self.first:
                self.outer += int(number(f.get("outer_iters"), 0))
                self.linear += int(number(f.get("linear_iters"), 0))
                self.steps += int(number(f.get("steps"), 0))
        self.max_residual = max((number(f.get("max_residual")) for f in frames
                                 if int(number(f.get("frame"), -1)) >= self.first), default=float("nan"))
        # time steps over the timed window (Gast et al. 2015 Fig. 18: min and average dt)
        dts = [number(r.get("dt")) for r in read_csv(os.path.join(d, "steps.csv")) or []
               if int(number(r.get("frame"), -1)) >= self.first]
        dts = [x for x in dts if math.isfinite(x)]
        self.min_dt = min(dts) if dts else float("nan")
        self.avg_dt = sum(dts) / len(dts) if dts else float("nan")
        self.timed = {k: t for k, t in self.frame_time.items() if k >= self.first}
        self.timed_wall = sum(self.timed.values())
        self.s_per_frame = self.timed_wall / len(self.timed) if self.timed else float("nan")
        worst = row.get("worst_solve_status", "")
        self.worst = self.status if self.status != "ok" else (worst or "none")
        self.clean = self.status == "ok" and number(row.get("converged_fraction"), 0.0) == 1.0


def load(root):
    cells_rows = read_csv(os.path.join(root, "cells.csv"))
    if cells_rows is None:
        die(f"{root}/cells.csv: not found (run `mpmbench matrix run FILE --out {root}` first)")
    try:
        with open(os.path.join(root, "matrix.json")) as f:
            meta = json.load(f)
    except (OSError, ValueError) as e:
        die(f"{root}/matrix.json: {e}")
    by_id = {}
    for r in cells_rows:
        by_id[r["id"]] = r  # the last row of an id wins
    return meta, [Cell(r, root) for r in by_id.values()]


def case_columns(cells):
    """Columns that identify a case: the cell settings in cells.csv order, up to the status."""
    if not cells:
        return []
    cols = []
    for c in cells[0].row:
        if c == "status":
            break
        if c not in CASE_SKIP and c not in SOLVER_AXES:
            cols.append(c)
    return cols


def group_cases(cells, cols):
    cases = {}
    for c in cells:
        cases.setdefault(tuple(c.row.get(k, "") for k in cols), []).append(c)
    return cases


def varying(cells, cols):
    """Columns with more than one value, without those the scene determines (per-scene settings)."""
    out = []
    for k in cols:
        if k == "scene" or len({c.row.get(k, "") for c in cells}) < 2:
            continue
        per_scene = {}
        for c in cells:
            per_scene.setdefault(c.row.get("scene", ""), set()).add(c.row.get(k, ""))
        if any(len(v) > 1 for v in per_scene.values()):
            out.append(k)
    return out


def scene_settings(cells, cols, show):
    """The settings that vary over the matrix but are fixed per scene, as text per scene."""
    fixed = [k for k in cols if k not in show and k != "scene" and len({c.row.get(k, "") for c in cells}) > 1]
    out = {}
    for c in cells:
        out.setdefault(c.row.get("scene", ""), ", ".join(f"{k}={c.row.get(k, '')}" for k in fixed))
    return out


def case_title(key, cols, show):
    vals = dict(zip(cols, key))
    parts = [vals.get("scene", "?")] + [f"{k}={vals[k]}" for k in show if k != "scene"]
    return " ".join(parts)


def speedups(cell, base):
    """Total and max per-frame speedup of cell against base (None when not comparable)."""
    if base is None or cell.status != "ok" or base.status != "ok" or not cell.timed or not base.timed:
        return None, None
    total = base.timed_wall / cell.timed_wall if cell.timed_wall > 0 else None
    per = [base.timed[k] / cell.timed[k] for k in cell.timed if k in base.timed and cell.timed[k] > 0]
    return total, (max(per) if per else None)


def solver_order(cells, baseline):
    seen = []
    for c in cells:
        if c.solver not in seen:
            seen.append(c.solver)
    if baseline in seen:
        seen.remove(baseline)
        seen.insert(0, baseline)
    return seen


def new_figure(plt, panels=1):
    fig, axes = plt.subplots(1, panels, figsize=(FIG_W, FIG_H), dpi=DPI)
    return fig, axes


def save(fig, root, name):
    os.makedirs(os.path.join(root, "figures"), exist_ok=True)
    path = os.path.join("figures", name)
    fig.savefig(os.path.join(root, path), dpi=DPI)
    return path


def profile_figure(plt, ratios, order):
    """The step curves rho_s(tau) of a Dolan-More profile from {solver: [ratios]} (inf = never),
    on a log2 tau axis; (None, None) with fewer than two solvers or no finite ratio."""
    finite = [r for rs in ratios.values() for r in rs if math.isfinite(r)]
    if len(order) < 2 or not finite:
        return None, None
    tau_max = max(2.0, max(finite) * 1.1)
    fig, ax = new_figure(plt)
    for s in order:
        rs = sorted(ratios.get(s, []))
        n = len(rs)
        if not n:
            continue
        xs, ys = [1.0], [0.0]
        for i, r in enumerate(rs):
            if not math.isfinite(r):
                break
            xs += [r, r]
            ys += [ys[-1], (i + 1) / n]
        xs.append(tau_max)
        ys.append(ys[-1])
        ax.plot(xs, ys, label=s, lw=1.6)
    ax.set_xscale("log", base=2)
    ax.set_xlim(1.0, tau_max)
    from matplotlib.ticker import ScalarFormatter
    ax.xaxis.set_major_formatter(ScalarFormatter())
    ax.set_ylim(0.0, 1.02)
    return fig, ax


def performance_profile(plt, root, cases, titles, order, md):
    """Dolan & More (2002): rho_s(tau) = share of cases with t_s <= tau * min_s t_s."""
    ratios = {s: [] for s in order}
    rows = []
    for key, cs in cases.items():
        t = {c.solver: (c.s_per_frame if c.clean and math.isfinite(c.s_per_frame) else math.inf) for c in cs}
        best = min(t.values()) if t else math.inf
        for s in order:
            if s not in t:
                continue
            r = t[s] / best if math.isfinite(best) and best > 0 else math.inf
            ratios[s].append(r)
            rows.append((titles[key], s, r))
    with open(os.path.join(root, "profile.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "solver", "ratio"])
        for case, s, r in rows:
            w.writerow([case, s, f"{r:.6f}" if math.isfinite(r) else "inf"])
    fig, ax = profile_figure(plt, ratios, order)
    if fig is None:
        return
    ax.set_xlabel("tau (s/frame within a factor tau of the best)")
    ax.set_ylabel("fraction of cases")
    ax.set_title(f"Performance profile over {len(cases)} cases")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    path = save(fig, root, "profile.png")
    plt.close(fig)
    md.append("\n## Performance profile\n")
    md.append("Fraction of cases in which each solver's s/frame is within a factor tau of the best solver's "
              "(Dolan & More 2002); a cell that did not end ok with every step converged never is.\n")
    md.append(markdown(["solver", "best (tau = 1)", "within 2x", "cases"],
                       [(s, fmt(sum(r <= 1.0 for r in ratios[s]) / len(ratios[s])),
                         fmt(sum(r <= 2.0 for r in ratios[s]) / len(ratios[s])), len(ratios[s]))
                        for s in order if ratios[s]]))
    md.append(f"\n![performance profile]({path})\n")


def frame_plot(plt, root, index, title, cs, order):
    if max((len(c.frame_time) for c in cs), default=0) < 2:
        return None
    fig, ax = new_figure(plt)
    first = min(c.first for c in cs)
    for s in order:
        for c in cs:
            if c.solver != s or not c.frame_time:
                continue
            ks = sorted(c.frame_time)
            ax.plot(ks, [c.frame_time[k] for k in ks], marker="o", ms=3, label=s)
    if first > 0:
        ax.axvspan(-0.5, first - 0.5, color="0.9", label="not timed")
    ax.set_xlabel("frame")
    ax.set_ylabel("wall seconds per frame")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    path = save(fig, root, f"frames_{index:02d}_{slug(title)}.png")
    plt.close(fig)
    return path


def stiffness_axis(meta):
    """A named set axis whose every value sets exactly one Young's modulus: (name, {label: E})."""
    for a in meta.get("named_axes", []):
        if a.get("kind") != "set":
            continue
        vals = {}
        for v in a.get("values", []):
            s = v.get("settings", {})
            keys = [k for k in s if k == "E" or k.endswith(".E")]
            if len(s) != 1 or len(keys) != 1 or not math.isfinite(number(s[keys[0]])):
                vals = None
                break
            vals[v["label"]] = number(s[keys[0]])
        if vals:
            return a["name"], vals
    return None, None


def stiffness_plots(plt, root, cells, cols, meta, order, md):
    name, moduli = stiffness_axis(meta)
    if not name or name not in cols:
        return
    rest = [k for k in cols if k != name]
    groups = group_cases(cells, rest)
    md.append(f"\n## Against stiffness ({name})\n")
    for i, (key, cs) in enumerate(sorted(groups.items())):
        title = case_title(key, rest, varying(cells, rest))
        fig, (a1, a2) = new_figure(plt, 2)
        for s in order:
            pts = sorted((moduli.get(c.row.get(name)), c) for c in cs if c.solver == s and c.row.get(name) in moduli)
            pts = [(e, c) for e, c in pts if c.status == "ok"]
            if not pts:
                continue
            es = [e for e, _ in pts]
            a1.plot(es, [c.s_per_frame for _, c in pts], marker="o", label=s)
            a2.plot(es, [c.outer for _, c in pts], marker="o", label=f"{s}")
        for a, lab in ((a1, "s/frame (timed window)"), (a2, "outer iterations (timed window)")):
            a.set_xscale("log")
            a.set_xlabel("Young's modulus [Pa]")
            a.set_ylabel(lab)
            a.grid(True, alpha=0.3)
        a1.legend(fontsize=7)
        fig.suptitle(title, fontsize=10)
        fig.tight_layout()
        path = save(fig, root, f"stiffness_{i:02d}_{slug(title)}.png")
        plt.close(fig)
        md.append(f"![time and iterations against stiffness, {title}]({path})\n")


def convergence_plot(plt, root, index, title, cs, order):
    curves = []
    for s in order:
        for c in cs:
            if c.solver != s:
                continue
            its = read_csv(os.path.join(c.dir, "iters.csv"))
            if not its:
                continue
            frame = min((int(number(r.get("frame"), 0)) for r in its if int(number(r.get("frame"), 0)) >= c.first),
                        default=None)
            if frame is None:
                continue
            pts = [r for r in its if int(number(r.get("frame"), -1)) == frame and int(number(r.get("step"), -1)) == 0]
            if pts:
                curves.append((s, frame, pts, number(c.row.get("eps"))))
    if not curves:
        return None
    fig, (a1, a2) = new_figure(plt, 2)
    for s, frame, pts, eps in curves:
        res = [max(number(r.get("residual")), 1e-300) for r in pts]
        a1.plot([number(r.get("elapsed_s")) for r in pts], res, label=s)
        a2.plot([int(number(r.get("iter"), 0)) for r in pts], res, label=s)
    eps = curves[0][3]
    for a, lab in ((a1, "seconds"), (a2, "outer iterations")):
        a.set_yscale("log")
        a.set_xlabel(lab)
        a.set_ylabel("CN residual")
        if math.isfinite(eps):
            a.axhline(eps, ls="--", color="0.4", lw=1)
        a.grid(True, alpha=0.3)
    a1.legend(fontsize=7)
    fig.suptitle(f"{title}: frame {curves[0][1]}, step 0", fontsize=10)
    fig.tight_layout()
    path = save(fig, root, f"convergence_{index:02d}_{slug(title)}.png")
    plt.close(fig)
    return path


def mg_table(cs, order):
    levels = {}
    for s in order:
        for c in cs:
            if c.solver == s:
                rows = read_csv(os.path.join(c.dir, "mg_levels.csv"))
                if rows:
                    levels[s] = rows
    if not levels:
        return None
    n = max(len(v) for v in levels.values())
    out = []
    for lv in range(n):
        line = [str(lv)]
        for s in levels:
            r = levels[s][lv] if lv < len(levels[s]) else None
            line.append(f"{number(r.get('blocks_per_row_avg')):.1f} / {r.get('blocks_per_row_max')} "
                        f"({int(number(r.get('nodes'), 0)):,} nodes)" if r else "-")
        out.append(line)
    return markdown(["level"] + list(levels), out)


def overview(md, cases, titles, order, baseline):
    """All cases at a glance: s/frame per solver, and speedups against the baseline (HOT Fig. 15)."""
    if len(cases) < 2:
        return
    md.append("## Overview\n")
    md.append("Seconds per frame over the timed window (`-`: the cell did not end ok):\n")
    rows = []
    for key, cs in sorted(cases.items()):
        by = {c.solver: c for c in cs}
        rows.append([titles[key]] + [fmt(by[s].s_per_frame) if s in by and by[s].status == "ok" else "-" for s in order])
    md.append(markdown(["case"] + order, rows))
    others = [s for s in order if s != baseline]
    if baseline and others:
        md.append(f"\nSpeedup against {baseline}, total / max per frame:\n")
        rows = []
        for key, cs in sorted(cases.items()):
            by = {c.solver: c for c in cs}
            line = [titles[key]]
            for s in others:
                total, per = speedups(by[s], by.get(baseline)) if s in by else (None, None)
                line.append(f"{fmt(total)} / {fmt(per)}")
            rows.append(line)
        md.append(markdown(["case"] + others, rows))
    md.append("")


def main(argv):
    if len(argv) != 2 or argv[1].startswith("-"):
        die("usage: mpmbench matrix report DIR")
    root = argv[1]
    meta, cells = load(root)
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        die(f"{sys.executable} has no matplotlib (Debian: apt-get install python3-matplotlib; "
            "in a virtual environment: pip install matplotlib)", 1)
    baseline = meta.get("baseline") or ""
    references = [c for c in cells if c.row.get("role") == "reference"]
    cells = [c for c in cells if c.row.get("role") != "reference"]
    cols = case_columns(cells)
    show = varying(cells, cols)
    cases = group_cases(cells, cols)
    order = solver_order(cells, baseline)
    md = [f"# Matrix {meta.get('name', '?')}\n"]
    if meta.get("description"):
        md.append(meta["description"] + "\n")
    counts = {}
    for c in cells:
        counts[c.status] = counts.get(c.status, 0) + 1
    md.append(f"{len(cells)} cells (" + ", ".join(f"{n} {s}" for s, n in sorted(counts.items())) + f"), "
              f"{len(cases)} cases; baseline solver: {baseline or 'none'}. Times are over each cell's timed "
              "window (frames from first_timed_frame on).\n")
    constant = [k for k in cols if len({c.row.get(k, "") for c in cells}) == 1]
    if cells and constant:
        md.append("Same in every cell: " + ", ".join(f"{k}={cells[0].row.get(k, '')}" for k in constant) + ".\n")
    try:
        with open(os.path.join(root, "provenance.json")) as f:
            inv = json.load(f).get("invocations", [])
        if inv:
            p = inv[-1]
            b = p.get("build", {})
            md.append(f"Last run: {p.get('start_time', '?')} on {p.get('host', '?')} ({p.get('cpu_model', '?')}, "
                      f"{p.get('cores_online', '?')} cores{ranks_text(p)}), build {b.get('git_commit', '?')[:12]}"
                      f"{' (dirty)' if b.get('git_dirty') else ''}, {b.get('compiler', '?')} {b.get('flags', '')}.\n")
    except (OSError, ValueError):
        pass

    table_rows = []
    titles = {key: case_title(key, cols, show) for key in cases}
    per_scene = scene_settings(cells, cols, show)
    overview(md, cases, titles, order, baseline)
    md.append("## Solvers per case\n")
    for i, (key, cs) in enumerate(sorted(cases.items())):
        title = titles[key]
        base = next((c for c in cs if c.solver == baseline), None)
        rows = []
        for s in order:
            for c in cs:
                if c.solver != s:
                    continue
                total, per = speedups(c, base)
                lin_step = c.linear / c.steps if c.steps else float("nan")
                setting = c.row.get("solver_setting", "")
                rows.append([f"{s} ({setting})" if setting else s, c.status, len(c.timed), fmt(c.s_per_frame), fmt(total), fmt(per), fmt(c.outer),
                             fmt(c.linear), fmt(lin_step), c.worst, fmt(c.min_dt), fmt(c.avg_dt),
                             fmt(c.max_residual)])
                table_rows.append({"case": title, "scene": c.row.get("scene", ""), "solver": s, "status": c.status,
                                   "timed_frames": len(c.timed), "s_per_frame": c.s_per_frame,
                                   "speedup_total": total, "speedup_max_frame": per, "outer_iters": c.outer,
                                   "linear_iters": c.linear, "linear_per_step": lin_step, "worst_status": c.worst,
                                   "min_dt": c.min_dt, "avg_dt": c.avg_dt, "max_residual": c.max_residual})
        md.append(f"### {title}\n")
        if per_scene.get(cs[0].row.get("scene", "")):
            md.append(f"({per_scene[cs[0].row.get('scene', '')]})\n")
        md.append(markdown(["solver", "status", "timed frames", "s/frame", f"speedup vs {baseline or '-'}",
                            "max per-frame speedup", "outer", "linear", "linear/step", "worst status", "min dt",
                            "avg dt", "max residual"], rows))
        fp = frame_plot(plt, root, i, title, cs, order)
        if fp:
            md.append(f"\n![frame times, {title}]({fp})\n")
        cp = convergence_plot(plt, root, i, title, cs, order)
        if cp:
            md.append(f"\n![convergence, {title}]({cp})\n")
        if meta.get("report_mg_levels"):
            t = mg_table(cs, order)
            if t:
                md.append("\nNonzero 3x3 blocks per row (mean / max) per multigrid level, last setup of the run "
                          "(HOT Fig. 8 counts scalar nonzeros, 3x these):\n\n" + t)
        md.append("")

    with open(os.path.join(root, "report.csv"), "w", newline="") as f:
        keys = ["case", "scene", "solver", "status", "timed_frames", "s_per_frame", "speedup_total",
                "speedup_max_frame", "outer_iters", "linear_iters", "linear_per_step", "worst_status", "min_dt",
                "avg_dt", "max_residual"]
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in table_rows:
            w.writerow({k: (f"{v:.6e}" if k in SMALL_COLUMNS and isinstance(v, float) and math.isfinite(v) else
                            f"{v:.6f}" if isinstance(v, float) and math.isfinite(v) else
                            "" if v is None or (isinstance(v, float) and not math.isfinite(v)) else v)
                        for k, v in r.items()})
    performance_profile(plt, root, cases, titles, order, md)
    stiffness_plots(plt, root, cells, cols, meta, order, md)
    sys.dont_write_bytecode = True  # no __pycache__ in the source tree
    import matrix_report_accuracy as accuracy
    helpers = {"fmt": fmt, "markdown": markdown, "slug": slug, "save": save, "new_figure": new_figure,
               "case_title": case_title, "varying": varying, "profile_figure": profile_figure}
    accuracy.work_precision(plt, root, cells, cols, order, md, helpers)
    accuracy.robustness(plt, root, md, order, helpers)
    if references:
        md.append("\n## Reference runs\n")
        md.append("The runs the cells' trajectories are compared with (their dt sequence is replayed):\n")
        md.append(markdown(["id", "scene", "solver", "eps", "status", "frames", "s/frame"],
                           [(c.id, c.row.get("scene", ""), c.solver, c.row.get("eps", ""), c.status,
                             len(c.frame_time), fmt(c.s_per_frame)) for c in references]))
    with open(os.path.join(root, "report.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print(f"wrote {root}/report.md, report.csv, profile.csv and {root}/figures/")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
