#!/usr/bin/env python3
"""Report of an experiment-matrix run: `mpmbench matrix report DIR` runs this
with the first Python that can import matplotlib of MPM_PYTHON, the python3
on PATH and /usr/bin/python3 (Debian: python3-matplotlib; or pip install
matplotlib in a virtual environment).

usage: matrix_report.py DIR

DIR is the --out directory of `mpmbench matrix run` (cells.csv, matrix.json,
cells/<id>/frames.csv, steps.csv and, when present, iters.csv and
mg_levels.csv; every table is read by column name). Writes

  DIR/report.md        the answer, one summary table, the figures, the detail;
  DIR/report.csv       one row per (case, solver) of the tables;
  DIR/summary.json     the answer lines and the summary table's numbers, for scripts;
  DIR/profile.csv      the performance-profile ratios (case, solver, ratio) of
                       the cases the profile compares;
  DIR/figures/*.png    with an .svg of the same figure beside each.

The report opens with its answer, computed from the cells: which solver is
fastest in how many cases, its speedup against the matrix's baseline
(geometric mean of the per-case s/frame ratios, with their range), how noisy
the times are, and the caveats (cells that did not end ok, cells run on a
busy machine, cases a profile leaves out); studies of one kind add their own
line (robustness: how many cells pass --check; stiffness: how s/frame changes
over the modulus; work precision: who reaches an error target first;
multigrid sparsity: blocks per row per level; two solvers: the ratio of
linear iterations per step). Then one summary table (a row per solver), the
figures, and the detail (settings, the overview and per-case tables).

Terms:
  * a case is one combination of every cell column but the solver (scene,
    eps, scale, threads, frames, timed window, named axes except
    "solver_setting", which holds per-solver settings such as a CFL number);
  * a cell's times are over its timed window (frames from first_timed_frame
    on) and over the frames it finished: a frame its run's time limit cut
    short (frames.csv complete = 0, or in older files status timeout with the
    --max-run-seconds reason) is not counted, and such a cell is
    "time-limit", not "ok";
  * with the matrix key "repeat" a cell ran N times: its s/frame is the
    median of the runs, and the min-max range is given; a ratio whose range
    includes 1 is not significant (marked ~). Without repeats a ratio within
    NOISE_FLOOR of 1 is marked ~ (the spread was not measured);
  * speedup against the baseline: the baseline's s/frame over the solver's
    (so it agrees with the s/frame columns), and the largest per-frame one
    over the frames both timed (HOT Fig. 15); both only when both cells
    ended ok with the same timed frames (then the largest per-frame speedup
    is never below the total);
  * a cell flagged machine_busy (other processes took CPU while it ran) keeps
    its row but its time is left out of the answer, the summary and the
    profile;
  * performance profile (Dolan & More 2002): the share of cases in which a
    solver's s/frame is within a factor tau of the best; it compares only the
    cases in which every solver ended ok with every step converged, to the
    case's eps (its largest CN residual at most eps), did work (outer
    iterations > 0) and ran on a quiet machine, and lists the cases it left
    out and why.

Figures: the speedup of every solver against the baseline over the cases;
the performance profile; where the time goes (s/frame split by phase, one
stacked bar per solver, per case); frame time per solver (log axis, HOT Fig.
11); s/frame and iterations against the modulus when a named set axis sets a
Young's modulus (a key ending in ".E"; HOT Fig. 20); residual against time
and against iterations for the cells run with --history (first step of the
first timed frame, HOT Figs. 15-17). With report.mg_levels in the matrix,
the blocks per row per multigrid level (HOT Fig. 8). A panel without data is
left out with a line saying why. Style: scripts/figure_style.py.

Accuracy (matrix_report_accuracy.py, beside this file): work precision and
the robustness grid of `matrix run --check`.

Exit status: 0; 2 for a directory without cells.csv/matrix.json or a Python
without matplotlib (`mpmbench matrix report` looks for one that has it); 1
for an internal failure (one line; MPM_TRACEBACK=1 prints the traceback).
Every error is one line with the prefix "mpmbench: error: matrix report:".
"""
import csv
import json
import math
import os
import re
import statistics
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
import figure_style as style  # noqa: E402 (after the bytecode switch)

STATUS_RANK = {"converged": 0, "capped": 1, "stalled": 2, "timeout": 3, "failed": 4}
CASE_SKIP = {"id", "solver", "set", "solver_opts", "role", "reference", "repeat"}  # not part of a case key
SMALL_COLUMNS = {"min_dt", "avg_dt", "max_residual"}  # written as %e in report.csv
# A named axis called "solver_setting" holds settings that belong to a solver
# rather than to the case (paired with solvers by include/exclude rules, e.g.
# the semi-implicit method's own CFL number in gast15-fig18.json): it is not
# part of the case key, so those cells are compared with the others.
SOLVER_AXES = {"solver_setting"}
# Single runs: a ratio within 10 % of 1 is not claimed (the run-to-run spread
# was not measured; give the matrix "repeat" to measure it).
NOISE_FLOOR = 1.10
# steps.csv phase columns, in the order of a step (the rest of wall_s is "other")
PHASES = [("p2g_s", "P2G"), ("assemble_s", "assemble"), ("setup_s", "setup"), ("solve_s", "solve"),
          ("linesearch_s", "line search"), ("g2p_s", "G2P")]
PHASE_COLOURS = ["#56B4E9", "#E69F00", "#CC79A7", "#0072B2", "#D55E00", "#009E73", "#BBBBBB"]


def ranks_text(invocation):
    """', mpirun: K ranks x J jobs' for a distributed run (provenance 'ranks' > 1), else ''."""
    ranks, jobs = invocation.get("ranks", 1), invocation.get("jobs_per_rank", 1)
    if not isinstance(ranks, int) or ranks <= 1:
        return ""
    return f", mpirun: {ranks} ranks x {jobs} job{'s' if jobs != 1 else ''}"


def die(msg, code=2):
    """One line with the program's common prefix, and the exit status (2: bad input)."""
    print(f"mpmbench: error: matrix report: {msg}", file=sys.stderr)
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


def fmt_ratio(x):
    return "-" if x is None or not math.isfinite(x) else f"{fmt(x)}x"


def markdown(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return "\n".join(out)


def slug(text):
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text)[:60]


def value_key(text):
    """Sort key of a cell value: numbers by value (1e-05 < 0.0001), then text."""
    v = number(text)
    return (0, v, "") if math.isfinite(v) else (1, 0.0, str(text))


def tuple_key(values):
    return tuple(value_key(v) for v in values)


def geomean(xs):
    xs = [x for x in xs if x is not None and math.isfinite(x) and x > 0]
    return math.exp(sum(math.log(x) for x in xs) / len(xs)) if xs else float("nan")


def frame_cut_short(f):
    """A frame the run's time limit cut short: frames.csv complete = 0, or (files written
    before that column) status timeout with the --max-run-seconds reason."""
    if "complete" in f and f.get("complete") not in (None, ""):
        return f.get("complete") == "0"
    return f.get("status") == "timeout" and "--max-run-seconds" in (f.get("reason") or "")


class Cell:
    """One cells.csv row (one run of a cell) and what its directory holds over the timed window."""

    def __init__(self, row, root):
        self.row = row
        self.id = row["id"]
        self.solver = row.get("solver", "?")
        self.first = int(number(row.get("first_timed_frame"), 0))
        self.status = row.get("status", "")
        self.eps = number(row.get("eps"))
        d = os.path.join(root, "cells", self.id)
        self.dir = d
        run = {}
        try:
            with open(os.path.join(d, "run.json")) as f:
                run = json.load(f)
        except (OSError, ValueError):
            pass
        # the counts the run used where the matrix left them to the scene / OpenMP (older cells.csv wrote 0)
        for col, key in (("frames_asked", "frames"), ("threads", "threads")):
            if row.get(col) == "0" and isinstance(run.get(key), int) and run[key] > 0:
                row[col] = str(run[key])
        frames = read_csv(os.path.join(d, "frames.csv")) or []
        self.frame_time = {}  # frame -> wall_s, every finished frame
        self.outer = self.linear = self.steps = 0
        self.cut_short = False
        finished = []
        for f in frames:
            if frame_cut_short(f):
                self.cut_short = True
                continue
            finished.append(f)
            k = int(number(f.get("frame"), -1))
            self.frame_time[k] = number(f.get("wall_s"), 0.0)
            if k >= self.first:
                self.outer += int(number(f.get("outer_iters"), 0))
                self.linear += int(number(f.get("linear_iters"), 0))
                self.steps += int(number(f.get("steps"), 0))
        asked = run.get("frames") if isinstance(run.get("frames"), int) else 0
        if frames and frames[-1].get("status") == "timeout" and 0 < len(finished) < asked and \
                "--max-run-seconds" in (frames[-1].get("reason") or "") + json.dumps(run.get("limits", {})):
            self.cut_short = True  # stopped at the limit exactly at a frame's end
        if self.status == "ok" and self.cut_short:
            self.status = "time-limit"  # older cells.csv said ok
        self.max_residual = max((number(f.get("max_residual")) for f in finished
                                 if int(number(f.get("frame"), -1)) >= self.first), default=float("nan"))
        steps = [r for r in read_csv(os.path.join(d, "steps.csv")) or []
                 if int(number(r.get("frame"), -1)) >= self.first and int(number(r.get("frame"), -1)) in self.frame_time]
        # time steps over the timed window (Gast et al. 2015 Fig. 18: min and average dt)
        dts = [x for x in (number(r.get("dt")) for r in steps) if math.isfinite(x)]
        self.min_dt = min(dts) if dts else float("nan")
        self.avg_dt = sum(dts) / len(dts) if dts else float("nan")
        # where the time goes: seconds per phase over the timed steps
        self.phase_s = {}
        if steps and all(c in steps[0] for c, _ in PHASES):
            for c, _ in PHASES:
                self.phase_s[c] = sum(number(r.get(c), 0.0) for r in steps)
            self.phase_s["other"] = max(0.0, sum(number(r.get("wall_s"), 0.0) for r in steps)
                                        - sum(self.phase_s.values()))
        self.timed = {k: t for k, t in self.frame_time.items() if k >= self.first}
        self.timed_wall = sum(self.timed.values())
        self.s_per_frame = self.timed_wall / len(self.timed) if self.timed else float("nan")
        worst = row.get("worst_solve_status", "")
        self.worst = self.status if self.status != "ok" else (worst or "none")
        self.clean = self.status == "ok" and number(row.get("converged_fraction"), 0.0) == 1.0
        self.busy = row.get("machine_busy") == "1"
        self.others_cpu = number(row.get("others_cpu_s"))
        self.repeat = int(number(row.get("repeat"), 1))
        # the repeats of this cell (set by merge_repeats): s/frame median and range
        self.runs, self.lo, self.hi = [self], self.s_per_frame, self.s_per_frame

    def met_eps(self):
        """Ended ok, every step converged, and to the cell's eps (its CN residual at most eps)."""
        return self.clean and not (self.max_residual > self.eps * (1 + 1e-9))


def merge_repeats(cells):
    """One Cell per set of repeats (same row but id and repeat): s/frame the median of the runs
    that ended ok on a quiet machine (all runs when none did), lo/hi their range, per-frame
    times the per-frame medians; status the worst of the runs."""
    groups = {}
    for c in cells:
        key = tuple((k, v) for k, v in c.row.items() if k not in ("id", "repeat") and k in CELL_SETTINGS)
        groups.setdefault(key, []).append(c)
    out = []
    for runs in groups.values():
        runs.sort(key=lambda c: c.repeat)
        c = runs[0]
        if len(runs) > 1:
            bad = [r for r in runs if r.status != "ok"]
            c.status = bad[0].status if bad else "ok"
            c.clean = all(r.clean for r in runs)
            c.worst = max((r.worst for r in runs), key=lambda s: STATUS_RANK.get(s, 5))
            good = [r for r in runs if r.status == "ok" and not r.busy] or runs
            c.busy = all(r.busy for r in runs)
            frames = sorted(set.intersection(*(set(r.timed) for r in good)))
            c.timed = {k: statistics.median(r.timed[k] for r in good) for k in frames}
            sp = [r.s_per_frame for r in good if math.isfinite(r.s_per_frame)]
            c.s_per_frame = statistics.median(sp) if sp else float("nan")
            c.lo, c.hi = (min(sp), max(sp)) if sp else (float("nan"), float("nan"))
            c.timed_wall = c.s_per_frame * len(c.timed) if c.timed else float("nan")
            c.runs = runs
        out.append(c)
    return out


CELL_SETTINGS = set()  # the cells.csv columns before "status" (filled by load)


def load(root):
    cells_rows = read_csv(os.path.join(root, "cells.csv"))
    if cells_rows is None:
        die(f"{root}/cells.csv: not found (run `mpmbench matrix run FILE --out {root}` first)")
    try:
        with open(os.path.join(root, "matrix.json")) as f:
            meta = json.load(f)
    except (OSError, ValueError) as e:
        die(f"{root}/matrix.json: {e}")
    # matrix.json of older runs cut the description at 1,023 characters; the file's own text is whole
    whole = (meta.get("matrix") or {}).get("description")
    if isinstance(whole, str) and len(whole) > len(meta.get("description") or ""):
        meta["description"] = whole
    by_id = {}
    for r in cells_rows:
        by_id[r["id"]] = r  # the last row of an id wins
    if cells_rows:
        for k in cells_rows[0]:
            if k == "status":
                break
            CELL_SETTINGS.add(k)
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
    return dict(sorted(cases.items(), key=lambda kv: tuple_key(kv[0])))


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


class Speedup:
    """The baseline's s/frame over the cell's (total), the largest per-frame ratio, the range
    over the repeats and whether the ratio is outside the noise."""

    def __init__(self, cell, base):
        self.total = self.per = self.lo = self.hi = None
        self.significant = None
        self.measured_spread = False
        if base is None or cell.status != "ok" or base.status != "ok" or not cell.timed or not base.timed:
            return
        if set(cell.timed) != set(base.timed) or not cell.s_per_frame > 0:
            return  # not the same frames: not comparable
        self.total = base.s_per_frame / cell.s_per_frame
        per = [base.timed[k] / cell.timed[k] for k in cell.timed if cell.timed[k] > 0]
        self.per = max(per) if per else None
        if len(cell.runs) > 1 or len(base.runs) > 1:
            self.measured_spread = True
            self.lo, self.hi = base.lo / cell.hi, base.hi / cell.lo
            self.significant = self.lo > 1.0 or self.hi < 1.0
        else:
            self.significant = self.total > NOISE_FLOOR or self.total < 1.0 / NOISE_FLOOR

    def text(self):
        if self.total is None:
            return "-"
        s = fmt(self.total)
        if self.measured_spread:
            s += f" ({fmt(self.lo)}-{fmt(self.hi)})"
        return s + ("" if self.significant or cell_is_baseline(self) else " ~")


def cell_is_baseline(sp):
    return sp.total == 1.0 and sp.lo in (None, 1.0) and sp.hi in (None, 1.0) and not sp.measured_spread


def solver_order(cells, baseline):
    seen = []
    for c in cells:
        if c.solver not in seen:
            seen.append(c.solver)
    if baseline in seen:
        seen.remove(baseline)
        seen.insert(0, baseline)
    return seen


# ---------------------------------------------------------------- figures

def new_figure(plt, panels=1, height=None, width=None):
    size = style.ONE_COLUMN if panels == 1 else style.TWO_COLUMNS
    fig, axes = plt.subplots(1, panels, figsize=(width or size[0], height or size[1]))
    return fig, axes


def save(fig, root, name):
    """figures/NAME (a .png) and the same figure as .svg beside it; returns the PNG's path."""
    os.makedirs(os.path.join(root, "figures"), exist_ok=True)
    path = os.path.join("figures", name)
    fig.savefig(os.path.join(root, path), metadata={"Software": None})
    fig.savefig(os.path.join(root, path[:-4] + ".svg"), metadata={"Date": None, "Creator": None})
    return path


LEGEND_ROW_IN = 0.17  # inches per legend row at 7-point type


def legend_rows(n, width_in):
    """Rows of a bottom legend of n entries on a figure width_in inches wide."""
    ncol = max(1, min(n, int(width_in / 1.45)))
    return ncol, (n + ncol - 1) // ncol


def legend_outside(fig, ax, n=None):
    """The figure's legend below its axes, in as many columns as fit, with the space reserved
    (so it covers no data and is not cut)."""
    handles, labels = ax.get_legend_handles_labels() if ax is not None else fig.axes[0].get_legend_handles_labels()
    if not labels:
        return
    w, h = fig.get_size_inches()
    ncol, rows = legend_rows(len(labels), w)
    fig.legend(handles, labels, loc="lower center", ncol=ncol, handlelength=2.2, columnspacing=1.0,
               bbox_to_anchor=(0.5, 0.0))
    frac = min(0.6, (rows * LEGEND_ROW_IN + 0.08) / h)
    fig.get_layout_engine().set(rect=(0, frac, 1, 1 - frac))  # left, bottom, width, height


def legend_height(n, width_in):
    """Extra figure height a bottom legend of n entries needs."""
    return legend_rows(n, width_in)[1] * LEGEND_ROW_IN + 0.1


def plain_log_y(ax):
    """Log y axis with tick labels as plain numbers (2, 5, 10 rather than 2 x 10^0); minor ticks
    at 2 and 5 labelled when the data span less than two decades."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
    lo, hi = ax.get_ylim()
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    if lo > 0 and hi / lo < 100:
        ax.yaxis.set_minor_locator(LogLocator(base=10, subs=(2.0, 5.0)))
        ax.yaxis.set_minor_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    else:
        ax.yaxis.set_minor_formatter(NullFormatter())


def profile_figure(plt, ratios, order):
    """The step curves rho_s(tau) of a Dolan-More profile from {solver: [ratios]} (inf = never),
    on a log2 tau axis; (None, None) with fewer than two solvers or no finite ratio."""
    finite = [r for rs in ratios.values() for r in rs if math.isfinite(r)]
    if len([s for s in order if ratios.get(s)]) < 2 or not finite:
        return None, None
    tau_max = max(2.0, max(finite) * 1.1)
    n_solvers = len([s for s in order if ratios.get(s)])
    fig, ax = new_figure(plt, height=style.ONE_COLUMN[1] + legend_height(n_solvers, style.ONE_COLUMN[0]))
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
        kw = style.line_kwargs(s, order)
        kw["markevery"] = list(range(2, len(xs) - 1, 2)) or None
        ax.plot(xs, ys, **kw)
    ax.set_xscale("log", base=2)
    ax.set_xlim(1.0, tau_max)
    from matplotlib.ticker import ScalarFormatter
    from matplotlib.ticker import FuncFormatter
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.set_ylim(0.0, 1.03)
    legend_outside(fig, ax, n_solvers)
    return fig, ax


def performance_profile(plt, root, cases, titles, order, md_fig, md_detail):
    """Dolan & More (2002) over the cases every solver ran to the same accuracy with work.
    Returns (compared cases, {title: why left out})."""
    ratios = {s: [] for s in order}
    rows, dropped = [], {}
    for key, cs in cases.items():
        why = []
        if len({c.solver for c in cs}) < 2:
            continue
        for c in cs:
            if not c.met_eps():
                why.append(f"{c.solver} " + (c.status if c.status != "ok" else
                                             "did not converge every step" if not c.clean else
                                             f"stopped at CN residual {fmt(c.max_residual)} > eps {fmt(c.eps)}"))
            elif c.outer == 0:
                why.append(f"{c.solver} did no work (0 outer iterations)")
            elif c.busy:
                why.append(f"{c.solver} ran on a busy machine")
        if why:
            dropped[titles[key]] = why
            continue
        t = {c.solver: c.s_per_frame for c in cs}
        best = min(t.values())
        for s in order:
            if s in t:
                r = t[s] / best if best > 0 else math.inf
                ratios[s].append(r)
                rows.append((titles[key], s, r))
    with open(os.path.join(root, "profile.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "solver", "ratio"])
        for case, s, r in rows:
            w.writerow([case, s, f"{r:.6f}" if math.isfinite(r) else "inf"])
    compared = len({r[0] for r in rows})
    fig, ax = profile_figure(plt, ratios, order)
    if fig is None:
        why = ("no case in which every solver ran to the case's eps with work on a quiet machine"
               if not compared else "fewer than two solvers")
        md_fig.append(f"No performance profile: {why}.\n")
    else:
        ax.set_xlabel("tau (s/frame within tau x the best)")
        ax.set_ylabel("share of cases")
        ax.set_title(f"Performance profile, {compared} cases")
        path = save(fig, root, "profile.png")
        plt.close(fig)
        md_fig.append(f"![performance profile]({path})\n")
        md_fig.append(f"Performance profile (Dolan & More 2002) over the {compared} cases in which every solver ended ok "
                      "with every step converged to the case's eps, did work and ran on a quiet machine: the share of "
                      "those cases in which a solver's s/frame is within tau times the best."
                      + (f" {len(dropped)} cases left out (listed under Detail)." if dropped else "") + "\n")
    if dropped:
        md_detail.append("\n### Cases the performance profile leaves out\n")
        for case, why in dropped.items():
            md_detail.append(f"- {case}: " + "; ".join(why))
        md_detail.append("")
    return compared, dropped


def speedup_figure(plt, root, cases, titles, order, baseline):
    """Speedup against the baseline per case (log axis), one marker per solver; the range of the
    repeats as a bar. None when no solver has a speedup."""
    others = [s for s in order if s != baseline]
    pts = {s: [] for s in others}
    keys = list(cases)
    for i, key in enumerate(keys):
        by = {c.solver: c for c in cases[key]}
        base = by.get(baseline)
        for s in others:
            if s in by and not by[s].busy and base is not None and not base.busy:
                sp = Speedup(by[s], base)
                if sp.total is not None:
                    pts[s].append((i, sp))
    if not any(pts.values()):
        return None
    n = len(keys)
    width = style.ONE_COLUMN[0] if len(others) <= 4 and n <= 16 else style.TWO_COLUMNS[0]
    fig, ax = new_figure(plt, width=width, height=max(1.6, 0.8 + 0.17 * n) + legend_height(len(others), width))
    for j, s in enumerate(others):
        if not pts[s]:
            continue
        off = (j - (len(others) - 1) / 2) * min(0.12, 0.7 / max(1, len(others)))
        kw = style.line_kwargs(s, order)
        kw["linestyle"] = "none"
        ys = [i + off for i, _ in pts[s]]
        xs = [sp.total for _, sp in pts[s]]
        ax.plot(xs, ys, **kw)
        for (i, sp) in pts[s]:
            if sp.measured_spread:
                ax.plot([sp.lo, sp.hi], [i + off] * 2, color=kw["color"], lw=0.8)
    ax.axvline(1.0, color="0.3", lw=0.8)
    ax.axvspan(1 / NOISE_FLOOR, NOISE_FLOOR, color="0.92", lw=0, zorder=0)
    ax.set_xscale("log")
    ax.set_yticks(range(n))
    ax.set_yticklabels([titles[k] for k in keys])
    ax.set_ylim(n - 0.5, -0.5)
    ax.set_xlabel(f"speedup against {baseline} (s/frame ratio; > 1: faster)")
    ax.grid(True, axis="x", which="both")
    ax.grid(False, axis="y")
    from matplotlib.ticker import FuncFormatter
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    legend_outside(fig, ax)
    ax.set_title(f"Speedup against {baseline} (grey band: within {NOISE_FLOOR:g}x, not claimed)",
                 fontsize=style.FONT_PT)
    path = save(fig, root, "speedup.png")
    plt.close(fig)
    return path


def phase_axes(ax, cs, order, legend=True):
    """Stacked horizontal bars: s/frame of each solver split by phase (steps.csv)."""
    rows = [c for s in order for c in cs if c.solver == s and c.phase_s and c.timed]
    if not rows:
        return False
    labels = [c.solver for c in rows]
    left = [0.0] * len(rows)
    names = [name for _, name in PHASES] + ["other"]
    for j, (col, name) in enumerate([(c, n) for c, n in PHASES] + [("other", "other")]):
        w = [c.phase_s.get(col, 0.0) / len(c.timed) for c in rows]
        ax.barh(range(len(rows)), w, left=left, color=PHASE_COLOURS[j], label=name,
                edgecolor="white", linewidth=0.3, height=0.7)
        left = [a + b for a, b in zip(left, w)]
    ax.set_yticks(range(len(rows)))
    ax.set_yticklabels(labels)
    ax.set_ylim(len(rows) - 0.5, -0.5)
    ax.set_xlabel("s/frame by phase")
    ax.grid(False, axis="y")
    return True


def case_figure(plt, root, index, title, cs, order):
    """Frame time per solver (log axis, integer frame ticks; HOT Fig. 11) beside where the time
    goes (stacked bars per solver); a panel without data is left out. (path, note)."""
    many = max((len(c.frame_time) for c in cs), default=0) >= 2
    phases = any(c.phase_s and c.timed for c in cs)
    if not many and not phases:
        return None, "no figure: no frame times"
    notes = []
    if not many:
        notes.append("no frame-time panel: one frame per cell")
    if not phases:
        notes.append("no phase panel: steps.csv has no phase columns")
    n_rows = len([c for c in cs if c.phase_s and c.timed])
    panels = 2 if many and phases else 1
    width = style.TWO_COLUMNS[0] if panels == 2 else style.ONE_COLUMN[0]
    n_leg = len({c.solver for c in cs}) if many else 0
    height = max(2.2, 0.9 + 0.17 * n_rows) + legend_height(n_leg + (7 if phases else 0), width)
    fig, axes = new_figure(plt, panels, height=height)
    axes = list(axes) if many and phases else [axes]
    if many:
        ax = axes[0]
        from matplotlib.ticker import MaxNLocator
        first = min(c.first for c in cs)
        for s in order:
            for c in cs:
                if c.solver != s or not c.frame_time:
                    continue
                ks = [k for k in sorted(c.frame_time) if c.frame_time[k] > 0]
                ax.plot(ks, [c.frame_time[k] for k in ks], **style.line_kwargs(s, order, ms=3))
        if first > 0:
            ax.axvspan(-0.5, first - 0.5, color="0.92", lw=0)
            ax.text(first / 2 - 0.5, 0.98, "not timed", transform=ax.get_xaxis_transform(), ha="center", va="top",
                    fontsize=style.FONT_PT - 1, color="0.4")
        ax.set_yscale("log")
        plain_log_y(ax)
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_xlabel("frame")
        ax.set_ylabel("wall seconds per frame")
    if phases:
        phase_axes(axes[-1], cs, order, legend=False)
    handles, labels = [], []
    for a in axes:
        h, l = a.get_legend_handles_labels()
        handles += h
        labels += l
    if handles:
        ncol, rows = legend_rows(len(labels), width)
        fig.legend(handles, labels, loc="lower center", ncol=ncol, handlelength=2.0, columnspacing=1.0)
        frac = min(0.6, (rows * LEGEND_ROW_IN + 0.08) / height)
        fig.get_layout_engine().set(rect=(0, frac, 1, 1 - frac))
    fig.suptitle(title, fontsize=style.FONT_PT + 1)
    path = save(fig, root, f"frames_{index:02d}_{slug(title)}.png")
    plt.close(fig)
    return path, "; ".join(notes)


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
    """s/frame and outer iterations against the modulus; returns the answer line's numbers
    {solver: (s at the lowest E, s at the highest E)} of the first group."""
    name, moduli = stiffness_axis(meta)
    if not name or name not in cols:
        return None
    rest = [k for k in cols if k != name]
    groups = group_cases(cells, rest)
    answer = None
    for i, (key, cs) in enumerate(groups.items()):
        title = case_title(key, rest, varying(cells, rest))
        fig, (a1, a2) = new_figure(plt, 2, height=style.TWO_COLUMNS[1] + legend_height(len(order), style.TWO_COLUMNS[0]))
        ends = {}
        for s in order:
            pts = sorted(((moduli.get(c.row.get(name)), c) for c in cs if c.solver == s and c.row.get(name) in moduli),
                         key=lambda p: p[0])
            pts = [(e, c) for e, c in pts if c.status == "ok" and not c.busy]
            if not pts:
                continue
            es = [e for e, _ in pts]
            a1.plot(es, [c.s_per_frame for _, c in pts], **style.line_kwargs(s, order))
            a2.plot(es, [c.outer for _, c in pts], **style.line_kwargs(s, order))
            if len(pts) >= 2:
                ends[s] = (pts[0][0], pts[0][1].s_per_frame, pts[-1][0], pts[-1][1].s_per_frame)
        for a, lab in ((a1, "s/frame (timed window)"), (a2, "outer iterations (timed window)")):
            a.set_xscale("log")
            a.set_xlabel("Young's modulus [Pa]")
            a.set_ylabel(lab)
        a1.set_yscale("log")
        plain_log_y(a1)
        legend_outside(fig, a1)
        fig.suptitle(title, fontsize=style.FONT_PT + 1)
        path = save(fig, root, f"stiffness_{i:02d}_{slug(title)}.png")
        plt.close(fig)
        md.append(f"![time and iterations against stiffness, {title}]({path})\n")
        if answer is None:
            answer = ends
    return answer


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
    fig, (a1, a2) = new_figure(plt, 2, height=style.TWO_COLUMNS[1] + legend_height(len(curves), style.TWO_COLUMNS[0]))
    for s, frame, pts, eps in curves:
        res = [max(number(r.get("residual")), 1e-300) for r in pts]
        kw = style.line_kwargs(s, order, ms=2.5)
        kw["markevery"] = max(1, len(pts) // 12)
        a1.plot([number(r.get("elapsed_s")) for r in pts], res, **kw)
        a2.plot([int(number(r.get("iter"), 0)) for r in pts], res, **kw)
    eps = curves[0][3]
    for a, lab in ((a1, "seconds into the step"), (a2, "outer iterations")):
        a.set_yscale("log")
        a.set_xlabel(lab)
        a.set_ylabel("CN residual")
        if math.isfinite(eps):
            a.axhline(eps, ls="--", color="0.4", lw=0.8)
            a.annotate(f"eps {eps:g}", xy=(1.0, eps), xycoords=("axes fraction", "data"), ha="right", va="bottom",
                       fontsize=style.FONT_PT - 1, color="0.3")
    legend_outside(fig, a1)
    fig.suptitle(f"{title}: frame {curves[0][1]}, step 0", fontsize=style.FONT_PT + 1)
    path = save(fig, root, f"convergence_{index:02d}_{slug(title)}.png")
    plt.close(fig)
    return path


def mg_levels(cs, order):
    levels = {}
    for s in order:
        for c in cs:
            if c.solver == s:
                rows = read_csv(os.path.join(c.dir, "mg_levels.csv"))
                if rows:
                    levels[s] = rows
    return levels


def mg_table(levels):
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


# ---------------------------------------------------------------- tables and answer

def overview(md, cases, titles, order, baseline):
    """All cases at a glance: s/frame per solver, and speedups against the baseline (HOT Fig. 15)."""
    if len(cases) < 2:
        return
    md.append("### Overview\n")
    md.append("Seconds per frame over the timed window (`-`: the cell did not end ok; `busy`: ran while other "
              "processes used the machine):\n")
    rows = []
    for key, cs in cases.items():
        by = {c.solver: c for c in cs}
        rows.append([titles[key]] + [
            (fmt(by[s].s_per_frame) + (" busy" if by[s].busy else "")) if s in by and by[s].status == "ok" else "-"
            for s in order])
    md.append(markdown(["case"] + order, rows))
    others = [s for s in order if s != baseline]
    if baseline and others:
        md.append(f"\nSpeedup against {baseline}, total / max per frame (~: inside the noise, not claimed):\n")
        rows = []
        for key, cs in cases.items():
            by = {c.solver: c for c in cs}
            line = [titles[key]]
            for s in others:
                sp = Speedup(by[s], by.get(baseline)) if s in by else Speedup(None, None)
                line.append(f"{sp.text()} / {fmt(sp.per)}" if sp.total is not None else "-")
            rows.append(line)
        md.append(markdown(["case"] + others, rows))
    md.append("")


def solver_summary(cases, order, baseline):
    """Per solver: cases, clean, fastest-in, speedup geometric mean and range, significant
    faster/slower/noise counts, busy cells."""
    out = {}
    for s in order:
        out[s] = {"cases": 0, "clean": 0, "fastest": 0, "ratios": [], "faster": 0, "slower": 0, "noise": 0,
                  "busy": 0, "s_per_frame": []}
    n_fast = 0
    for key, cs in cases.items():
        by = {c.solver: c for c in cs}
        for s, c in by.items():
            o = out[s]
            o["cases"] += 1
            o["clean"] += c.clean
            o["busy"] += c.busy
        ok = [c for c in cs if c.met_eps() and not c.busy and math.isfinite(c.s_per_frame)]
        if len(ok) >= 2:
            n_fast += 1
            best = min(ok, key=lambda c: c.s_per_frame)
            out[best.solver]["fastest"] += 1
        base = by.get(baseline)
        for s, c in by.items():
            if base is None or base.busy or c.busy:
                continue
            sp = Speedup(c, base)
            if sp.total is None:
                continue
            out[s]["ratios"].append(sp.total)
            if s != baseline:
                out[s]["faster" if sp.significant and sp.total > 1 else "slower" if sp.significant else "noise"] += 1
    return out, n_fast


def answer_lines(summary, n_fast, order, baseline, cells, cases, repeat, dropped, compared, extra, lead=()):
    """The report's first lines (markdown bullets), every number computed from the cells; `lead`
    are the lines of the study's own question (robustness, accuracy), which come first."""
    lines = list(lead)
    ranked = sorted(order, key=lambda s: (-summary[s]["fastest"], -geomean(summary[s]["ratios"])))
    if n_fast and len(order) > 1:
        w = ranked[0]
        line = f"**Fastest: {w}**, in {summary[w]['fastest']} of {n_fast} cases (among the cells that met the case's eps)"
        if baseline and w != baseline and summary[w]["ratios"]:
            line += f"; against {baseline} it is " + ratio_text(summary[w]["ratios"])
        elif baseline and w == baseline:
            line += " (the baseline)"
        lines.append(line + ".")
        if len(ranked) >= 2 and (summary[ranked[1]]["fastest"] or w == baseline):
            r = ranked[1]
            line = f"Next: {r}, fastest in {summary[r]['fastest']}"
            if baseline and r != baseline and summary[r]["ratios"]:
                line += f"; against {baseline} " + ratio_text(summary[r]["ratios"])
            lines.append(line + ".")
    elif cells:
        lines.append(f"{len(cells)} cells of {len(order)} solver{'s' if len(order) != 1 else ''}; no case has two "
                     "solvers that ended ok to compare.")
    lines += extra
    if baseline and len(order) > 1:
        sig = sum(summary[s]["faster"] + summary[s]["slower"] for s in order if s != baseline)
        noise = sum(summary[s]["noise"] for s in order if s != baseline)
        if repeat > 1:
            lines.append(f"Noise: every cell ran {repeat} times; times are medians with the min-max range. "
                         f"{noise} of {sig + noise} speedups against {baseline} have a range that includes 1 "
                         "(marked ~, not significant).")
        else:
            lines.append(f"Noise: every cell ran once, so the run-to-run spread was not measured (matrix key "
                         f"`repeat`); {noise} of {sig + noise} speedups against {baseline} are within "
                         f"{NOISE_FLOOR:g}x of 1 and are not claimed (marked ~).")
    caveats = []
    bad = {}
    for c in cells:
        if c.status != "ok":
            bad[c.status] = bad.get(c.status, 0) + 1
    if bad:
        caveats.append(f"{sum(bad.values())} of {len(cells)} cells did not end ok ("
                       + ", ".join(f"{n} {s}" for s, n in sorted(bad.items())) + ")")
    unconv = sum(1 for c in cells if c.status == "ok" and not c.clean)
    if unconv:
        caveats.append(f"{unconv} cell{'s' if unconv != 1 else ''} ended ok with some step not converged")
    busy = sum(1 for c in cells for r in c.runs if r.busy)
    if busy:
        caveats.append(f"{busy} cell run{'s' if busy != 1 else ''} on a busy machine (their times are left out)")
    if dropped:
        caveats.append(f"the performance profile compares {compared} of {compared + len(dropped)} cases "
                       f"(left out: a solver stopped at another accuracy, did no work, failed or ran on a busy "
                       f"machine)")
    if caveats:
        lines.append("Caveats: " + "; ".join(caveats) + ".")
    elif cells:
        lines.append(f"All {len(cells)} cells ended ok with every step converged.")
    return lines


def ratio_text(rs):
    """'1.44x as fast (geometric mean of the s/frame ratios over 13 cases, 1.22x to 5.56x)'."""
    if len(rs) == 1:
        return f"{fmt(rs[0])}x as fast (s/frame ratio, 1 case)"
    return (f"{fmt(geomean(rs))}x as fast (geometric mean of the s/frame ratios over {len(rs)} cases, "
            f"{fmt(min(rs))}x to {fmt(max(rs))}x)")


def _json_num(x):
    return round(x, 6) if x is not None and math.isfinite(x) else None


def stiffness_answer(ends, order):
    if not ends:
        return None
    parts = []
    e0 = e1 = None
    for s in order:
        if s in ends:
            e0, t0, e1, t1 = ends[s]
            parts.append((t1 / t0, s))
    if not parts:
        return None
    parts.sort()
    least, most = parts[0], parts[-1]
    return (f"Stiffness: from E = {e0:.0e} to {e1:.0e} Pa, s/frame changes least for {least[1]} ({fmt(least[0])}x) and "
            f"most for {most[1]} ({fmt(most[0])}x).")


def mg_answer(levels_by_case):
    for title, levels in levels_by_case:
        if not levels:
            continue
        parts = []
        for s, rows in levels.items():
            coarse = rows[-1]
            parts.append(f"{s} {number(rows[0].get('blocks_per_row_avg')):.0f} on level 0 and "
                         f"{number(coarse.get('blocks_per_row_avg')):.0f} on level {len(rows) - 1}")
        return f"Sparsity ({title}): mean nonzero 3x3 blocks per row, " + "; ".join(parts) + "."
    return None


def iterations_answer(cases, order):
    """With exactly two solvers: the ratio of linear iterations per step (HOT Table 3)."""
    if len(order) != 2:
        return None
    a, b = order
    rs = []
    for cs in cases.values():
        by = {c.solver: c for c in cs}
        if a in by and b in by and by[a].linear > 0 and by[b].linear > 0 and by[a].steps and by[b].steps:
            rs.append((by[b].linear / by[b].steps) / (by[a].linear / by[a].steps))
    if not rs:
        return None
    if len(rs) == 1:
        return f"Linear iterations per step: {b} takes {fmt(rs[0])}x those of {a}."
    return (f"Linear iterations per step: {b} takes {fmt(geomean(rs))}x those of {a} (geometric mean over "
            f"{len(rs)} cases, {fmt(min(rs))}x to {fmt(max(rs))}x).")


def summary_table(summary, order, baseline, check_pass):
    header = ["solver", "cases", "ended ok, converged", "fastest in"]
    if baseline:
        header += [f"speedup vs {baseline}: geo. mean (range)", "faster / slower / ~"]
    if check_pass:
        header.append("--check passed")
    rows = []
    for s in order:
        o = summary[s]
        line = [s, o["cases"], o["clean"], o["fastest"]]
        if baseline:
            rs = o["ratios"]
            line.append((f"{fmt(geomean(rs))} ({fmt(min(rs))}-{fmt(max(rs))})" if len(rs) > 1 else fmt(rs[0]))
                        if rs and s != baseline
                         else "1 (baseline)" if s == baseline else "-")
            line.append("" if s == baseline else f"{o['faster']} / {o['slower']} / {o['noise']}")
        if check_pass:
            p, t = check_pass.get(s, (0, 0))
            line.append(f"{p}/{t}")
        rows.append(line)
    return markdown(header, rows)


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
        die(f"{sys.executable} cannot import matplotlib (Debian: apt-get install python3-matplotlib; in a virtual "
            "environment: pip install matplotlib; or set MPM_PYTHON to a python3 that has it)")
    style.apply(matplotlib)
    baseline = meta.get("baseline") or ""
    repeat = int(number((meta.get("matrix") or {}).get("repeat"), 1))
    references = [c for c in cells if c.row.get("role") == "reference"]
    runs = [c for c in cells if c.row.get("role") != "reference"]
    cells = merge_repeats(runs)
    cols = case_columns(cells)
    show = varying(cells, cols)
    cases = group_cases(cells, cols)
    order = solver_order(cells, baseline)
    titles = {key: case_title(key, cols, show) for key in cases}
    per_scene = scene_settings(cells, cols, show)

    md_fig, md_detail = [], []
    # ---- detail: settings
    if meta.get("description"):
        md_detail.append(meta["description"] + "\n")
    counts = {}
    for c in runs:
        counts[c.status] = counts.get(c.status, 0) + 1
    md_detail.append(f"{len(runs)} cell runs (" + ", ".join(f"{n} {s}" for s, n in sorted(counts.items())) + ")"
                     + (f", {repeat} per cell" if repeat > 1 else "") + f", {len(cases)} cases; baseline solver: "
                     f"{baseline or 'none'}. Times are over each cell's timed window (frames from first_timed_frame "
                     "on) and over the frames it finished.\n")
    constant = [k for k in cols if len({c.row.get(k, "") for c in cells}) == 1]
    if cells and constant:
        md_detail.append("Same in every cell: " + ", ".join(f"{k}={cells[0].row.get(k, '')}" for k in constant) + ".\n")
    try:
        with open(os.path.join(root, "provenance.json")) as f:
            inv = json.load(f).get("invocations", [])
        if inv:
            p = inv[-1]
            b = p.get("build", {})
            md_detail.append(f"Last run: {p.get('start_time', '?')} on {p.get('host', '?')} ({p.get('cpu_model', '?')}, "
                             f"{p.get('cores_online', '?')} cores{ranks_text(p)}), build {b.get('git_commit', '?')[:12]}"
                             f"{' (dirty)' if b.get('git_dirty') else ''}, {b.get('compiler', '?')} "
                             f"{b.get('flags', '')}.\n")
    except (OSError, ValueError):
        pass
    if any("machine_busy" in c.row for c in runs):
        busy = [c for c in runs if c.busy]
        md_detail.append(f"Machine load: {len(busy)} of {len(runs)} cell runs ran while other processes took more "
                         "CPU than the cores the cell left free (cells.csv machine_busy, others_cpu_s)"
                         + (": " + ", ".join(f"{c.id} ({c.row.get('scene')}/{c.solver}, "
                                             f"{fmt(c.others_cpu)} s of others' CPU)" for c in busy[:20]) if busy
                            else "") + ".\n")
    else:
        md_detail.append("Machine load: not recorded (cells.csv from before the machine_busy column).\n")

    overview(md_detail, cases, titles, order, baseline)

    # ---- figures
    if baseline and len(order) > 1:
        sp_path = speedup_figure(plt, root, cases, titles, order, baseline)
        if sp_path:
            md_fig.append(f"![speedup against {baseline}]({sp_path})\n")
            md_fig.append(f"Speedup of each solver against {baseline} per case (s/frame ratio; "
                          + ("bars: the range over the repeats" if repeat > 1 else "single runs") + ").\n")
        else:
            md_fig.append(f"No speedup figure: no case in which {baseline} and another solver both ended ok on a "
                          "quiet machine.\n")
    compared, dropped = performance_profile(plt, root, cases, titles, order, md_fig, md_detail)
    ends = stiffness_plots(plt, root, cells, cols, meta, order, md_fig)

    # ---- detail: per case
    md_detail.append("### Solvers per case\n")
    table_rows = []
    levels_by_case = []
    for i, (key, cs) in enumerate(cases.items()):
        title = titles[key]
        base = next((c for c in cs if c.solver == baseline), None)
        rows = []
        for s in order:
            for c in cs:
                if c.solver != s:
                    continue
                sp = Speedup(c, base)
                lin_step = c.linear / c.steps if c.steps else float("nan")
                setting = c.row.get("solver_setting", "")
                spf = fmt(c.s_per_frame) + (f" ({fmt(c.lo)}-{fmt(c.hi)})" if len(c.runs) > 1 else "")
                rows.append([f"{s} ({setting})" if setting else s, c.status + (" busy" if c.busy else ""),
                             len(c.timed), spf, sp.text(), fmt(sp.per), fmt(c.outer), fmt(c.linear), fmt(lin_step),
                             c.worst, fmt(c.min_dt), fmt(c.avg_dt), fmt(c.max_residual)])
                table_rows.append({"case": title, "scene": c.row.get("scene", ""), "solver": s, "status": c.status,
                                   "timed_frames": len(c.timed), "s_per_frame": c.s_per_frame,
                                   "s_per_frame_min": c.lo, "s_per_frame_max": c.hi, "runs": len(c.runs),
                                   "speedup_total": sp.total, "speedup_max_frame": sp.per,
                                   "speedup_significant": "" if sp.significant is None else int(sp.significant),
                                   "outer_iters": c.outer, "linear_iters": c.linear, "linear_per_step": lin_step,
                                   "worst_status": c.worst, "min_dt": c.min_dt, "avg_dt": c.avg_dt,
                                   "max_residual": c.max_residual, "machine_busy": int(c.busy)})
        md_detail.append(f"#### {title}\n")
        if per_scene.get(cs[0].row.get("scene", "")):
            md_detail.append(f"({per_scene[cs[0].row.get('scene', '')]})\n")
        md_detail.append(markdown(["solver", "status", "timed frames", "s/frame", f"speedup vs {baseline or '-'}",
                                   "max per-frame speedup", "outer", "linear", "linear/step", "worst status",
                                   "min dt", "avg dt", "max residual"], rows))
        fp, note = case_figure(plt, root, i, title, cs, order)
        if fp:
            md_detail.append(f"\n![frame times and phases, {title}]({fp})\n")
        if note:
            md_detail.append(f"\n({note}.)\n")
        cp = convergence_plot(plt, root, i, title, cs, order)
        if cp:
            md_fig.append(f"![convergence, {title}]({cp})\n")
        if meta.get("report_mg_levels"):
            levels = mg_levels(cs, order)
            levels_by_case.append((title, levels))
            t = mg_table(levels)
            if t:
                md_detail.append("\nNonzero 3x3 blocks per row (mean / max) per multigrid level, last setup of the run "
                                 "(HOT Fig. 8 counts scalar nonzeros, 3x these):\n\n" + t)
        md_detail.append("")

    with open(os.path.join(root, "report.csv"), "w", newline="") as f:
        keys = ["case", "scene", "solver", "status", "timed_frames", "s_per_frame", "s_per_frame_min",
                "s_per_frame_max", "runs", "speedup_total", "speedup_max_frame", "speedup_significant", "outer_iters",
                "linear_iters", "linear_per_step", "worst_status", "min_dt", "avg_dt", "max_residual", "machine_busy"]
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in table_rows:
            w.writerow({k: (f"{v:.6e}" if k in SMALL_COLUMNS and isinstance(v, float) and math.isfinite(v) else
                            f"{v:.6f}" if isinstance(v, float) and math.isfinite(v) else
                            "" if v is None or (isinstance(v, float) and not math.isfinite(v)) else v)
                        for k, v in r.items()})

    import matrix_report_accuracy as accuracy
    helpers = {"fmt": fmt, "markdown": markdown, "slug": slug, "save": save, "new_figure": new_figure,
               "case_title": case_title, "varying": varying, "profile_figure": profile_figure,
               "style": style, "value_key": value_key, "legend_outside": legend_outside,
               "legend_height": legend_height}
    wp_answer = accuracy.work_precision(plt, root, cells, cols, order, md_fig, md_detail, helpers)
    check_pass, rb_answer = accuracy.robustness(plt, root, md_fig, md_detail, order, helpers)
    if references:
        md_detail.append("\n### Reference runs\n")
        md_detail.append("The runs the cells' trajectories are compared with (their dt sequence is replayed):\n")
        md_detail.append(markdown(["id", "scene", "solver", "eps", "status", "frames", "s/frame"],
                                  [(c.id, c.row.get("scene", ""), c.solver, c.row.get("eps", ""), c.status,
                                    len(c.frame_time), fmt(c.s_per_frame)) for c in references]))

    # ---- the answer first
    summary, n_fast = solver_summary(cases, order, baseline)
    lead = [x for x in (rb_answer, wp_answer) if x]
    extra = [x for x in (stiffness_answer(ends, order), mg_answer(levels_by_case), iterations_answer(cases, order))
             if x]
    lines = answer_lines(summary, n_fast, order, baseline, cells, cases, repeat, dropped, compared, extra, lead)
    # the same numbers for scripts (the README's numbers are filled in from these)
    with open(os.path.join(root, "summary.json"), "w") as f:
        json.dump({"name": meta.get("name", ""), "baseline": baseline, "repeat": repeat,
                   "cells": len(runs), "cases": len(cases),
                   "status": {k: v for k, v in sorted(counts.items())},
                   "machine_busy": sum(1 for c in runs if c.busy),
                   "profile_cases": compared, "profile_left_out": len(dropped),
                   "answer": lines,
                   "solvers": {s: {"cases": summary[s]["cases"], "ended_ok_converged": summary[s]["clean"],
                                   "fastest_in": summary[s]["fastest"], "fastest_of": n_fast,
                                   "speedup_geomean": _json_num(geomean(summary[s]["ratios"])),
                                   "speedup_min": _json_num(min(summary[s]["ratios"], default=float("nan"))),
                                   "speedup_max": _json_num(max(summary[s]["ratios"], default=float("nan"))),
                                   "speedup_cases": len(summary[s]["ratios"]),
                                   "faster": summary[s]["faster"], "slower": summary[s]["slower"],
                                   "within_noise": summary[s]["noise"],
                                   "check_passed": list(check_pass[s]) if check_pass and s in check_pass else None}
                               for s in order}}, f, indent=1)
    md = [f"# {meta.get('name', '?')}: what it found\n"]
    md += [f"- {x}" for x in lines]
    md.append("\n## Summary\n")
    md.append(summary_table(summary, order, baseline, check_pass))
    md.append("\n(cases: cases the solver ran; fastest in: cases where its s/frame is the smallest among the cells that "
              "ended ok with every step converged to the case's eps on a quiet machine; speedup: the baseline's s/frame over the solver's, over the cases both "
              "ended ok with the same frames" + (f"; faster / slower: outside the noise, ~: inside it" if baseline else "")
              + ".)\n")
    md.append("## Figures\n")
    md += md_fig or ["No figures: nothing to compare.\n"]
    md.append("## Detail\n")
    md += md_detail
    with open(os.path.join(root, "report.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print(f"wrote {root}/report.md, report.csv, summary.json, profile.csv and {root}/figures/")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv))
    except Exception as e:  # a bug or an unreadable file: one line, status 1 (internal failure)
        if os.environ.get("MPM_TRACEBACK"):
            raise
        import traceback
        where = traceback.extract_tb(e.__traceback__)[-1]
        die(f"internal failure: {type(e).__name__}: {e} (at {os.path.basename(where.filename)}:{where.lineno} in "
            f"{where.name}; MPM_TRACEBACK=1 prints the traceback)".replace("\n", " "), 1)
