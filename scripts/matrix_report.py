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
fastest in how many cases (by more than the noise: closer cases are ties, and
named), its speedup against the matrix's baseline (geometric mean of the
per-case s/frame ratios, with their range and how many are faster, slower or
within the noise), how noisy the times are, and the caveats (cells that did
not end ok or did not converge, cells run on a busy machine, cases a profile
leaves out, settings the matrix's description states that the cells did not
run with); when no case has two cells to rank it says why (all busy, not
converged, failed) rather than ranking; studies of one kind add their own
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
  * a cell may be ranked when it ended ok with every step converged to the
    case's eps on a quiet machine. A cell flagged machine_busy (other
    processes took CPU while it ran) or not converged keeps its numbers,
    marked "busy" / "not converged" wherever they appear (tables, speedups,
    figure labels; ringed / crossed points), but is left out of the answer,
    the summary's counts and speedups and the profile;
  * fastest in a case: the smallest s/frame of the cells that may be ranked,
    counted only when it beats the next by more than the noise (the ranges of
    the repeats do not overlap; without repeats by more than NOISE_FLOOR);
    otherwise the case is a tie of the fastest and those within the noise of
    it;
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
left out with a line saying why; a title or label wider than the figure is
wrapped (fit_texts); log axes get plain tick labels spaced so they never
overlap. Style: scripts/figure_style.py. main(argv, figure_hook) hands every
figure, laid out as it is saved, to figure_hook first
(tests/matrix/test_report_figures.sh checks their extents there).

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


def plural(n, word, words=None):
    """'1 case', '2 cases' ('1 cell run', '3 cell runs'; words: an irregular plural)."""
    return f"{n:,} {word if n == 1 else words or word + 's'}"


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
    """A file-name part from a case title: a scene file's folders and its ".json" left out
    (stiffness_00_sphere-on-box.png, not ..._sphere-on-box.json.png)."""
    text = re.sub(r"(?:[^\s/]*/)+(?=[^\s/]*\.json\b)", "", text)  # the folders of a scene file
    text = re.sub(r"\.json\b", "", text)
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
        self.run = run  # run.json as read ({} when missing): settings and provenance
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

    def eligible(self):
        """Its time may be ranked: met the case's eps, on a quiet machine, with a time."""
        return self.met_eps() and not self.busy and self.s_per_frame > 0

    def marks(self):
        """The words that go with this cell's numbers wherever they appear: "busy" (ran on a busy
        machine: its time is not claimed) and "not converged" (ended ok with some step not
        converged, or above the case's eps)."""
        out = []
        if self.busy:
            out.append("busy")
        if self.status == "ok" and not self.met_eps():
            out.append("not converged")
        return out


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
    CELL_SETTINGS.clear()
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


def clearly_faster(a, b):
    """a's s/frame is below b's by more than the noise: with repeats (either cell) the min-max
    ranges do not overlap (a's slowest run is faster than b's fastest), else by more than
    NOISE_FLOOR. The same rule as Speedup.significant."""
    if len(a.runs) > 1 or len(b.runs) > 1:
        return a.hi < b.lo
    return b.s_per_frame > NOISE_FLOOR * a.s_per_frame


def case_ranking(cs):
    """The fastest cell of a case among those that may be ranked (Cell.eligible), and the cells
    within the noise of it (tied, the fastest first): a win counts only when `tied` is the
    fastest alone. None with fewer than two such cells."""
    ok = sorted((c for c in cs if c.eligible()), key=lambda c: c.s_per_frame)
    if len(ok) < 2:
        return None
    tied = [ok[0]] + [c for c in ok[1:] if not clearly_faster(ok[0], c)]
    return {"best": ok[0], "next": ok[1], "tied": tied, "clear": len(tied) == 1}


def noise_words(repeat):
    return f"the min-max spread of the {repeat} runs" if repeat > 1 else f"the {NOISE_FLOOR:g}x noise band"


class Speedup:
    """The baseline's s/frame over the cell's (total), the largest per-frame ratio, the range
    over the repeats and whether the ratio is outside the noise; `marks` the words of either
    cell (busy, not converged) that qualify it."""

    def __init__(self, cell, base):
        self.total = self.per = self.lo = self.hi = None
        self.significant = None
        self.measured_spread = False
        self.marks = []
        for c in (cell, base):
            for m in (c.marks() if c is not None else []):
                if m not in self.marks:
                    self.marks.append(m)
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
        s += "" if self.significant or cell_is_baseline(self) else " ~"
        return s + "".join(f" {m}" for m in self.marks)

    def claimed(self):
        """Both cells may be ranked (met eps on a quiet machine): the ratio counts in the answer."""
        return self.total is not None and not self.marks


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


# Called with (figure, its path under DIR) just before a figure is saved, after fit_texts laid it
# out as savefig will (main's figure_hook; tests/matrix/test_report_figures.sh checks the extents
# of every text there). When it returns False the figure is not written.
FIGURE_HOOK = None


def _layout_texts(fig):
    """The texts fit_texts may wrap: the suptitle, axes titles and x labels (horizontal)."""
    out = [fig._suptitle] if getattr(fig, "_suptitle", None) is not None else []
    for ax in fig.axes:
        out += [ax.title, getattr(ax, "_left_title", None), getattr(ax, "_right_title", None), ax.xaxis.label]
    return [t for t in out if t is not None and t.get_visible() and t.get_text()]


def fit_texts(fig):
    """Lays the figure out as savefig will and wraps a title or x label that does not fit the
    canvas onto more lines (a long case title, a long solver name in a label), so no text is cut."""
    import textwrap
    for _ in range(3):
        fig.canvas.draw()
        r = fig.canvas.get_renderer()
        w = fig.bbox.width
        changed = False
        for t in _layout_texts(fig):
            bb = t.get_window_extent(r)
            if bb.x0 >= 0 and bb.x1 <= w:
                continue
            cx = (bb.x0 + bb.x1) / 2
            room = 0.94 * (2 * min(cx, w - cx) if t.get_ha() == "center" else w)
            lines = t.get_text().split("\n")
            longest = max(len(x) for x in lines)
            chars = max(12, int(longest * room / max(bb.width, 1.0)))
            t.set_text("\n".join(textwrap.fill(x, chars) for x in lines))
            changed = True
        if not changed:
            return


def save(fig, root, name):
    """figures/NAME (a .png) and the same figure as .svg beside it; returns the PNG's path."""
    os.makedirs(os.path.join(root, "figures"), exist_ok=True)
    path = os.path.join("figures", name)
    fit_texts(fig)
    if FIGURE_HOOK is not None and FIGURE_HOOK(fig, path) is False:
        return path
    fig.savefig(os.path.join(root, path), metadata={"Software": None})
    fig.savefig(os.path.join(root, path[:-4] + ".svg"), metadata={"Date": None, "Creator": None})
    return path


LEGEND_ROW_IN = 0.17  # inches per legend row at 7-point type
LEGEND_CHAR_IN = 0.056  # inches per character of a legend label at 7-point type (wide glyphs)
LEGEND_HANDLE_IN = 0.5  # the handle, its padding and the column spacing


def legend_rows(n, width_in, labels=None):
    """(columns, rows) of a bottom legend of n entries on a figure width_in inches wide: as many
    columns as the longest label lets fit."""
    longest = max((len(x) for x in labels), default=12) if labels else 12
    col_in = LEGEND_HANDLE_IN + LEGEND_CHAR_IN * longest
    ncol = max(1, min(n, int((width_in - 0.1) / col_in)))
    return ncol, (n + ncol - 1) // ncol


def legend_below(fig, handles, labels):
    """The figure's legend below its axes, in as many columns as fit, with the space reserved
    (so it covers no data and is not cut)."""
    if not labels:
        return
    w, h = fig.get_size_inches()
    ncol, rows = legend_rows(len(labels), w, labels)
    fig.legend(handles, labels, loc="lower center", ncol=ncol, handlelength=2.2, columnspacing=1.0,
               bbox_to_anchor=(0.5, 0.0))
    frac = min(0.6, (rows * LEGEND_ROW_IN + 0.08) / h)
    fig.get_layout_engine().set(rect=(0, frac, 1, 1 - frac))  # left, bottom, width, height


def legend_outside(fig, ax, n=None, extra=()):
    """legend_below with the entries of ax (or the first axes) and `extra` (handle, label) pairs."""
    handles, labels = ax.get_legend_handles_labels() if ax is not None else fig.axes[0].get_legend_handles_labels()
    for h, lab in extra:
        handles.append(h)
        labels.append(lab)
    legend_below(fig, handles, labels)


def legend_height(n, width_in, labels=None):
    """Extra figure height a bottom legend of n entries needs."""
    return legend_rows(n, width_in, labels)[1] * LEGEND_ROW_IN + 0.1


# Cells whose numbers are not claimed, drawn over their points in every figure of points
# (speedup, stiffness, work precision): a grey ring for a cell run on a busy machine, a cross for
# one with some step not converged; the legend says so.
MARK_STYLE = {"busy": {"marker": "o", "markersize": 9, "markerfacecolor": "none", "markeredgecolor": "0.45",
                       "markeredgewidth": 0.9, "linestyle": "none"},
              "not converged": {"marker": "x", "markersize": 6, "color": "0.1", "markeredgewidth": 1.0,
                                "linestyle": "none"}}
MARK_LABEL = {"busy": "ringed: busy machine", "not converged": "crossed: not converged"}


def mark_points(ax, pts):
    """Overlays the marks of [(x, y, marks)]; returns the set of marks drawn."""
    drawn = set()
    for m, kw in MARK_STYLE.items():
        xy = [(x, y) for x, y, ms in pts if m in ms]
        if xy:
            ax.plot([x for x, _ in xy], [y for _, y in xy], zorder=4, **kw)
            drawn.add(m)
    return drawn


def mark_legend(drawn):
    """(handle, label) pairs of the marks drawn, for legend_outside."""
    from matplotlib.lines import Line2D
    return [(Line2D([], [], **MARK_STYLE[m]), MARK_LABEL[m]) for m in MARK_STYLE if m in drawn]


def marked_label(name, marks):
    """A solver's legend or tick label with its cell's marks: 'hot (busy)'."""
    return style.short_name(name) + (f" ({', '.join(marks)})" if marks else "")


def nice_log_ticks(lo, hi, room_in, extent=lambda t: 0.16):
    """Ticks of a log axis from lo to hi, the densest set whose labels (extent(tick): inches along
    the axis) fit room_in inches without touching: round linear steps within a short range (1.5,
    2, 2.5, 3), then the mantissas 1-9, 1-2-5, 1-3, powers of ten, every k-th power of ten."""
    if not (lo > 0 and hi > lo):
        return []
    decade_in = room_in / math.log10(hi / lo)
    e0, e1 = math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1

    def fits(ticks):
        return len(ticks) >= 2 and all(math.log10(b / a) * decade_in > (extent(a) + extent(b)) / 2
                                       for a, b in zip(ticks, ticks[1:]))

    def inside(ticks):
        return [t for t in ticks if lo * (1 - 1e-9) <= t <= hi * (1 + 1e-9)]

    sets = []
    if hi / lo < 10:
        step0 = 10.0 ** math.floor(math.log10(hi - lo))
        for k in (0.1, 0.2, 0.25, 0.5, 1.0, 2.0, 2.5, 5.0):
            st = step0 * k
            sets.append(inside([round(i * st, 12) for i in range(max(1, math.floor(lo / st)), math.ceil(hi / st) + 1)]))
    for mults in ((1, 2, 3, 4, 5, 6, 7, 8, 9), (1, 2, 5), (1, 3), (1,)):
        sets.append(inside([float(f"{m}e{e}") for e in range(e0, e1 + 1) for m in mults]))
    for step in (2, 3, 5, 10):
        sets.append(inside([float(f"1e{e}") for e in range(e0, e1 + 1) if e % step == 0]))
    for ticks in sets:
        if len(ticks) <= 12 and fits(ticks):
            return ticks
    return min((t for t in sets if t), key=len, default=[])


def tick_text(v):
    """A tick label as a plain number: 0.5, 2, 1e+05 for the large and small."""
    return f"{v:g}"


def plain_log_axis(ax, which="y"):
    """A log axis labelled with plain numbers at the ticks nice_log_ticks chooses for the axis's
    length (no minor labels), so the labels fit and never overlap."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter
    fig = ax.figure
    ax.autoscale_view()
    lo, hi = ax.get_ylim() if which == "y" else ax.get_xlim()
    lo, hi = min(lo, hi), max(lo, hi)
    w, h = fig.get_size_inches()
    pos = ax.get_position()
    room = pos.height * h if which == "y" else pos.width * w
    axis = ax.yaxis if which == "y" else ax.xaxis
    # a label's extent along the axis: its height (7-point type) or its width (about 0.06 inch a
    # character), with a gap
    extent = (lambda t: 0.16) if which == "y" else (lambda t: 0.06 * len(tick_text(t)) + 0.08)
    ticks = nice_log_ticks(lo, hi, max(room, 0.8), extent)
    if len(ticks) >= 1:
        axis.set_major_locator(FixedLocator(ticks))
    axis.set_major_formatter(FuncFormatter(lambda v, _: tick_text(v)))
    axis.set_minor_formatter(NullFormatter())


def plain_log_y(ax):
    plain_log_axis(ax, "y")


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
    repeats as a bar; cells not claimed (busy, not converged) marked. (path or None, [cases not
    shown, with why])."""
    others = [s for s in order if s != baseline]
    rows, left_out = [], []
    for key in cases:
        by = {c.solver: c for c in cases[key]}
        base = by.get(baseline)
        pts = [(s, Speedup(by[s], base)) for s in others if s in by]
        pts = [(s, sp) for s, sp in pts if sp.total is not None]
        if pts:
            rows.append((key, pts))
        elif any(s in by for s in others):
            left_out.append(f"{titles[key]} (" + (f"no {baseline} cell" if base is None else
                                                  f"{baseline} {base.status}" if base.status != "ok" else
                                                  "no other solver ended ok with the same timed frames") + ")")
    if not rows:
        return None, left_out
    n = len(rows)
    longest = max(len(titles[k]) for k, _ in rows)
    width = style.ONE_COLUMN[0] if len(others) <= 4 and n <= 16 and longest <= 22 else style.TWO_COLUMNS[0]
    drawn = {m for _, pts in rows for _, sp in pts for m in sp.marks}
    legend_labels = others + [MARK_LABEL[m] for m in drawn] + [f"within {NOISE_FLOOR:g}x: not claimed"]
    height = 1.25 + 0.19 * n + legend_height(len(legend_labels), width, legend_labels)
    fig, ax = new_figure(plt, width=width, height=height)
    xs_all = [1 / NOISE_FLOOR, NOISE_FLOOR]
    marked = []
    for j, s in enumerate(others):
        mine = [(i, sp) for i, (_, pts) in enumerate(rows) for name, sp in pts if name == s]
        if not mine:
            continue
        off = (j - (len(others) - 1) / 2) * min(0.12, 0.7 / max(1, len(others)))
        kw = style.line_kwargs(s, order)
        kw["linestyle"] = "none"
        ax.plot([sp.total for _, sp in mine], [i + off for i, _ in mine], **kw)
        for i, sp in mine:
            xs_all.append(sp.total)
            marked.append((sp.total, i + off, sp.marks))
            if sp.measured_spread:
                ax.plot([sp.lo, sp.hi], [i + off] * 2, color=kw["color"], lw=0.8)
                xs_all += [sp.lo, sp.hi]
    mark_points(ax, marked)
    ax.axvline(1.0, color="0.3", lw=0.8)
    from matplotlib.patches import Patch
    ax.axvspan(1 / NOISE_FLOOR, NOISE_FLOOR, color="0.9", lw=0, zorder=0)
    ax.set_xscale("log")
    lo, hi = min(xs_all), max(xs_all)
    pad = (hi / lo) ** 0.06
    ax.set_xlim(lo / pad, hi * pad)
    ax.set_yticks(range(n))
    ax.set_yticklabels([titles[k] for k, _ in rows])
    ax.set_ylim(n - 0.5, -0.5)
    ax.set_xlabel(f"speedup against {baseline} (> 1: faster)")
    ax.grid(True, axis="x", which="major")
    ax.grid(False, axis="y")
    plain_log_axis(ax, "x")
    ax.set_xlim(lo / pad, hi * pad)
    legend_outside(fig, ax, extra=mark_legend(drawn) + [(Patch(color="0.9"), legend_labels[-1])])
    ax.set_title(f"Speedup against {baseline}", fontsize=style.FONT_PT)
    path = save(fig, root, "speedup.png")
    plt.close(fig)
    return path, left_out


def phase_axes(ax, cs, order, legend=True):
    """Stacked horizontal bars: s/frame of each solver split by phase (steps.csv); a cell's marks
    (busy, not converged) in its label."""
    rows = [c for s in order for c in cs if c.solver == s and c.phase_s and c.timed]
    if not rows:
        return False
    labels = [marked_label(c.solver, c.marks()) for c in rows]
    left = [0.0] * len(rows)
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
    goes (stacked bars per solver); a panel without data is left out; a cell's marks (busy, not
    converged) in its labels. (path, note)."""
    many = max((len([k for k, t in c.frame_time.items() if t > 0]) for c in cs), default=0) >= 2
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
    first = min(c.first for c in cs)
    labels = ([marked_label(c.solver, c.marks()) for s in order for c in cs if c.solver == s] if many else [])
    labels += ["not timed"] if many and first > 0 else []
    labels += [name for _, name in PHASES] + ["other"] if phases else []
    height = max(2.2, 0.9 + 0.17 * n_rows) + legend_height(len(labels), width, labels)
    fig, axes = new_figure(plt, panels, height=height)
    axes = list(axes) if many and phases else [axes]
    extra = []
    if many:
        ax = axes[0]
        from matplotlib.patches import Patch
        from matplotlib.ticker import MaxNLocator
        for s in order:
            for c in cs:
                if c.solver != s or not c.frame_time:
                    continue
                ks = [k for k in sorted(c.frame_time) if c.frame_time[k] > 0]
                kw = style.line_kwargs(s, order, ms=3)
                kw["label"] = marked_label(s, c.marks())
                ax.plot(ks, [c.frame_time[k] for k in ks], **kw)
        if first > 0:
            ax.axvspan(-0.5, first - 0.5, color="0.92", lw=0)
            extra.append((Patch(color="0.92"), "not timed"))
        ax.set_yscale("log")
        plain_log_y(ax)
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_xlabel("frame")
        ax.set_ylabel("wall seconds per frame")
    if phases:
        phase_axes(axes[-1], cs, order, legend=False)
    handles, labels = [], []
    for k, a in enumerate(axes):
        h, l = a.get_legend_handles_labels()
        handles += h
        labels += l
        if k == 0:
            handles += [h for h, _ in extra]
            labels += [l for _, l in extra]
    legend_below(fig, handles, labels)
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
    """s/frame and outer iterations against the modulus, cells not claimed marked (busy: the time
    panel; not converged: both); a group without a point is left out with a line saying why.
    Returns the answer line's numbers {solver: (E lowest, s there, E highest, s there)} of the
    first group, from the cells that may be ranked."""
    name, moduli = stiffness_axis(meta)
    if not name or name not in cols:
        return None
    rest = [k for k in cols if k != name]
    groups = group_cases(cells, rest)
    answer = None
    for i, (key, cs) in enumerate(groups.items()):
        title = case_title(key, rest, varying(cells, rest))
        lines = {}
        for s in order:
            pts = sorted(((moduli[c.row.get(name)], c) for c in cs if c.solver == s and c.row.get(name) in moduli
                          and c.status == "ok" and c.s_per_frame > 0), key=lambda p: p[0])
            if pts:
                lines[s] = pts
        if not lines:
            md.append(f"No stiffness figure for {title}: no cell ended ok.\n")
            continue
        labels = list(lines)
        drawn = {m for pts in lines.values() for _, c in pts for m in c.marks()}
        labels += [MARK_LABEL[m] for m in drawn]
        fig, (a1, a2) = new_figure(plt, 2, height=style.TWO_COLUMNS[1] + legend_height(len(labels), style.TWO_COLUMNS[0],
                                                                                       labels))
        ends = {}
        marks1, marks2 = [], []
        for s, pts in lines.items():
            es = [e for e, _ in pts]
            a1.plot(es, [c.s_per_frame for _, c in pts], **style.line_kwargs(s, order))
            a2.plot(es, [c.outer for _, c in pts], **style.line_kwargs(s, order))
            marks1 += [(e, c.s_per_frame, c.marks()) for e, c in pts]
            marks2 += [(e, c.outer, [m for m in c.marks() if m != "busy"]) for e, c in pts]
            good = [(e, c) for e, c in pts if c.eligible()]
            if len(good) >= 2:
                ends[s] = (good[0][0], good[0][1].s_per_frame, good[-1][0], good[-1][1].s_per_frame)
        mark_points(a1, marks1)
        mark_points(a2, marks2)
        for a, lab in ((a1, "s/frame (timed window)"), (a2, "outer iterations (timed window)")):
            a.set_xscale("log")
            a.set_xlabel("Young's modulus [Pa]")
            a.set_ylabel(lab)
        a1.set_yscale("log")
        plain_log_y(a1)
        legend_outside(fig, a1, extra=mark_legend(drawn))
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
                curves.append((s, frame, pts, number(c.row.get("eps")), c.marks()))
    if not curves:
        return None
    labels = [marked_label(s, marks) for s, _, _, _, marks in curves]
    fig, (a1, a2) = new_figure(plt, 2, height=style.TWO_COLUMNS[1] + legend_height(len(curves), style.TWO_COLUMNS[0],
                                                                                   labels))
    for (s, frame, pts, eps, marks), label in zip(curves, labels):
        res = [max(number(r.get("residual")), 1e-300) for r in pts]
        kw = style.line_kwargs(s, order, ms=2.5)
        kw["markevery"] = max(1, len(pts) // 12)
        kw["label"] = label
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

MARKS_KEY = ("`busy`: ran on a busy machine (other processes took CPU the cell needed), so its time is not "
             "claimed; `not converged`: ended ok with some step not converged to the case's eps")


def overview(md, cases, titles, order, baseline):
    """All cases at a glance: s/frame per solver, and speedups against the baseline (HOT Fig. 15);
    every number with its cell's marks (busy, not converged)."""
    if len(cases) < 2:
        return
    md.append("### Overview\n")
    md.append(f"Seconds per frame over the timed window (`-`: the cell did not end ok; {MARKS_KEY}):\n")
    rows = []
    for key, cs in cases.items():
        by = {c.solver: c for c in cs}
        rows.append([titles[key]] + [
            " ".join([fmt(by[s].s_per_frame)] + by[s].marks()) if s in by and by[s].status == "ok" else "-"
            for s in order])
    md.append(markdown(["case"] + order, rows))
    others = [s for s in order if s != baseline]
    if baseline and others:
        md.append(f"\nSpeedup against {baseline}, total / max per frame (~: inside the noise, not claimed; "
                  "busy, not converged: either cell):\n")
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
    """Per solver: cases, clean, busy, fastest (by more than the noise) and tied-for-fastest
    counts, the claimed speedups against the baseline (both cells met eps on a quiet machine) with
    their faster/slower/noise counts. Returns (summary, ranking facts of the cases)."""
    out = {}
    for s in order:
        out[s] = {"cases": 0, "clean": 0, "fastest": 0, "tied": 0, "ratios": [], "faster": 0, "slower": 0,
                  "noise": 0, "busy": 0, "unconverged": 0}
    facts = {"compared": 0, "clear": 0, "ties": [], "not_compared": {}}
    for key, cs in cases.items():
        by = {c.solver: c for c in cs}
        for s, c in by.items():
            o = out[s]
            o["cases"] += 1
            o["clean"] += c.clean
            o["busy"] += c.busy
            o["unconverged"] += "not converged" in c.marks()
        rk = case_ranking(cs)
        if rk:
            facts["compared"] += 1
            if rk["clear"]:
                facts["clear"] += 1
                out[rk["best"].solver]["fastest"] += 1
            else:
                facts["ties"].append((key, [c.solver for c in rk["tied"]]))
                for c in rk["tied"]:
                    out[c.solver]["tied"] += 1
        elif len(by) >= 2:
            for c in cs:
                why = why_not_ranked(c)
                if why:
                    facts["not_compared"][why] = facts["not_compared"].get(why, 0) + 1
        base = by.get(baseline)
        for s, c in by.items():
            sp = Speedup(c, base)
            if not sp.claimed():
                continue
            out[s]["ratios"].append(sp.total)
            if s != baseline:
                out[s]["faster" if sp.significant and sp.total > 1 else "slower" if sp.significant else "noise"] += 1
    return out, facts


def why_not_ranked(c):
    """Why a cell's time is not ranked, in words ('' when it is)."""
    if c.status != "ok":
        return "did not end ok"
    if not c.met_eps():
        return "ended ok with some step not converged to the case's eps"
    if c.busy:
        return "ran on a busy machine"
    if not c.s_per_frame > 0:
        return "has no timed frame"
    return ""


def versus_text(s, summary, baseline):
    """'; against B it is 1.44x as fast (geometric mean ...; faster in 3, within the noise in 1)'."""
    o = summary[s]
    if not baseline or s == baseline or not o["ratios"]:
        return ""
    counts = [f"faster in {o['faster']}", f"slower in {o['slower']}", f"within the noise in {o['noise']}"]
    counts = [x for x, n in zip(counts, (o["faster"], o["slower"], o["noise"])) if n]
    return f"; against {baseline} it is " + ratio_text(o["ratios"])[:-1] + "; " + ", ".join(counts) + ")"


def answer_lines(summary, facts, order, baseline, cells, cases, repeat, dropped, compared, extra, lead=(),
                 description_notes=()):
    """The report's first lines (markdown bullets), every number computed from the cells; `lead`
    are the lines of the study's own question (robustness, accuracy), which come first. A solver
    is fastest in a case only by more than the noise (NOISE_FLOOR, or the runs' ranges with
    repeats) over the next; closer cases are ties, and said so."""
    lines = list(lead)
    n_cmp = facts["compared"]
    noise = noise_words(repeat)
    ranked = sorted(order, key=lambda s: (-summary[s]["fastest"], -summary[s]["tied"], -geomean(summary[s]["ratios"])))
    if n_cmp and len(order) > 1:
        w = ranked[0]
        if summary[w]["fastest"]:
            line = (f"**Fastest: {w}**, ahead of every other solver by more than {noise} in "
                    f"{summary[w]['fastest']} of {plural(n_cmp, 'case')} compared")
            if summary[w]["tied"]:
                line += f", tied for fastest (within the noise) in {summary[w]['tied']} more"
            line += " (the baseline)" if w == baseline else versus_text(w, summary, baseline)
            lines.append(line + ".")
        else:
            lines.append(f"**No clear fastest solver**: in {'each' if n_cmp > 1 else 'the'} of the "
                         f"{plural(n_cmp, 'case')} compared the fastest solvers are within {noise} of each other.")
        if facts["ties"]:
            shown = facts["ties"][:5]
            lines.append(f"Ties (the fastest within {noise} of each other) in {len(facts['ties'])} of "
                         f"{plural(n_cmp, 'case')}: "
                         + "; ".join(f"{case_title_of(k, cases)} ({', '.join(ss)})" for k, ss in shown)
                         + (f"; and {len(facts['ties']) - len(shown)} more (Detail)" if len(facts["ties"]) > 5 else "")
                         + ".")
        if summary[w]["fastest"] and len(ranked) >= 2:
            r = ranked[1]
            if summary[r]["fastest"] or summary[r]["tied"] or w == baseline:
                parts = ([f"fastest by more than the noise in {summary[r]['fastest']}"] if summary[r]["fastest"] else
                         []) + ([f"tied for fastest in {summary[r]['tied']}"] if summary[r]["tied"] else [])
                line = f"Next: {r}" + (", " + ", ".join(parts) if parts else "")
                line += versus_text(r, summary, baseline).replace(" it is ", " ")
                lines.append(line + ".")
    elif cells:
        lines.append(no_ranking_line(cells, order, facts))
    lines += extra
    if baseline and len(order) > 1:
        sig = sum(summary[s]["faster"] + summary[s]["slower"] for s in order if s != baseline)
        nz = sum(summary[s]["noise"] for s in order if s != baseline)
        if sig + nz == 0:
            pass
        elif repeat > 1:
            lines.append(f"Noise: every cell ran {repeat} times; times are medians with the min-max range. "
                         f"{nz} of {plural(sig + nz, 'speedup')} against {baseline} "
                         f"{'has' if sig + nz == 1 else 'have'} a range that includes 1 (marked ~, not significant).")
        else:
            lines.append(f"Noise: every cell ran once, so the run-to-run spread was not measured (matrix key "
                         f"`repeat`); {nz} of {plural(sig + nz, 'speedup')} against {baseline} "
                         f"{'is' if sig + nz == 1 else 'are'} within {NOISE_FLOOR:g}x of 1 and not claimed (marked ~).")
    caveats = list(description_notes)
    bad = {}
    for c in cells:
        if c.status != "ok":
            bad[c.status] = bad.get(c.status, 0) + 1
    if bad:
        caveats.append(f"{sum(bad.values())} of {plural(len(cells), 'cell')} did not end ok ("
                       + ", ".join(f"{n} {s}" for s, n in sorted(bad.items())) + ")")
    unconv = sum(1 for c in cells if c.status == "ok" and not c.clean)
    if unconv:
        caveats.append(f"{plural(unconv, 'cell')} ended ok with some step not converged (marked not converged)")
    busy = sum(1 for c in cells for r in c.runs if r.busy)
    if busy:
        caveats.append(f"{plural(busy, 'cell run')} on a busy machine (marked busy"
                       + ("; left out of the ranking and the speedups above)" if n_cmp else ")"))
    if facts["not_compared"] and n_cmp:
        caveats.append("cases not compared: " + ", ".join(f"{plural(n, 'cell')} {why}"
                                                         for why, n in facts["not_compared"].items()))
    if dropped:
        caveats.append(f"the performance profile compares {compared} of {plural(compared + len(dropped), 'case')} "
                       f"(left out: a solver stopped at another accuracy, did no work, failed or ran on a busy "
                       f"machine)")
    if caveats:
        lines.append("Caveats: " + "; ".join(caveats) + ".")
    elif cells:
        lines.append(f"All {plural(len(cells), 'cell')} ended ok with every step converged"
                     + (" on a quiet machine." if any("machine_busy" in r.row for c in cells for r in c.runs) else "."))
    return lines


def case_title_of(key, cases):
    return CASE_TITLES.get(key, " ".join(key))


CASE_TITLES = {}  # case key -> title (set by main)


def no_ranking_line(cells, order, facts):
    """The opening line when no case has two cells to rank: what is true of the cells."""
    if len(order) < 2:
        return (f"{plural(len(cells), 'cell')} of one solver ({order[0] if order else '?'}): no solvers to rank; "
                "the tables compare its settings.")
    why = {}
    for c in cells:
        w = why_not_ranked(c)
        if w:
            why[w] = why.get(w, 0) + 1
    if list(why) == ["ran on a busy machine"] and why["ran on a busy machine"] == len(cells):
        return (f"**No ranking**: all {plural(len(cells), 'cell')} ran on a busy machine (other processes took CPU "
                "they needed), so their times are not compared; the tables and figures show them marked busy. "
                "Rerun on an idle machine (README, Running benchmarks).")
    if not why:
        return f"{plural(len(cells), 'cell')} of {plural(len(order), 'solver')}; no case has two of them to compare."
    return (f"**No ranking**: no case has two solvers that ended ok with every step converged on a quiet machine; of "
            f"the {plural(len(cells), 'cell')}, " + ", ".join(f"{n} {w}" for w, n in why.items()) + ".")


def case_rank_line(cs, repeat):
    """The ranking of one case in words: who is fastest by more than the noise, or the tie, or
    why it is not ranked ('' with one solver)."""
    if len({c.solver for c in cs}) < 2:
        return ""
    rk = case_ranking(cs)
    if rk is None:
        why = [f"{c.solver} {why_not_ranked(c)}" for c in cs if why_not_ranked(c)]
        return "Not ranked: " + "; ".join(why) + "."
    best, nxt = rk["best"], rk["next"]
    margin = nxt.s_per_frame / best.s_per_frame
    spread = (f", runs {fmt(best.lo)}-{fmt(best.hi)} against {fmt(nxt.lo)}-{fmt(nxt.hi)} s/frame"
              if len(best.runs) > 1 or len(nxt.runs) > 1 else "")
    if rk["clear"]:
        return (f"Fastest: {best.solver}, {fmt(margin)}x ahead of {nxt.solver} (more than {noise_words(repeat)}"
                f"{spread}).")
    return (f"No clear fastest: {', '.join(c.solver for c in rk['tied'])} within {noise_words(repeat)} of each other "
            f"({best.solver} {fmt(margin)}x ahead of {nxt.solver}{spread}).")


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
    if len(parts) == 1:
        return f"Stiffness: from E = {e0:.0e} to {e1:.0e} Pa, s/frame changes {fmt(least[0])}x for {least[1]}."
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
        if a in by and b in by and by[a].status == by[b].status == "ok" and by[a].linear > 0 and by[b].linear > 0 \
                and by[a].steps and by[b].steps:
            rs.append((by[b].linear / by[b].steps) / (by[a].linear / by[a].steps))
    if not rs:
        return None
    if len(rs) == 1:
        return f"Linear iterations per step: {b} takes {fmt(rs[0])}x those of {a}."
    return (f"Linear iterations per step: {b} takes {fmt(geomean(rs))}x those of {a} (geometric mean over "
            f"{len(rs)} cases, {fmt(min(rs))}x to {fmt(max(rs))}x).")


def summary_table(summary, order, baseline, check_pass):
    """One row per solver; the speedups and the fastest counts are over the cells that may be
    ranked (met eps on a quiet machine), and a column counts the cells that were not (busy, not
    converged) when there are any."""
    marked = any(summary[s]["busy"] or summary[s]["unconverged"] for s in order)
    header = ["solver", "cases", "ended ok, converged", "fastest in (tied)"]
    if marked:
        header.append("busy / not converged")
    if baseline:
        header += [f"speedup vs {baseline}: geo. mean (range), cases", "faster / slower / ~"]
    if check_pass:
        header.append("--check passed")
    rows = []
    for s in order:
        o = summary[s]
        line = [s, o["cases"], o["clean"], f"{o['fastest']}" + (f" ({o['tied']})" if o["tied"] else "")]
        if marked:
            line.append(f"{o['busy']} / {o['unconverged']}")
        if baseline:
            rs = o["ratios"]
            line.append((f"{fmt(geomean(rs))} ({fmt(min(rs))}-{fmt(max(rs))}), {len(rs)}" if len(rs) > 1 else
                         f"{fmt(rs[0])}, 1") if rs and s != baseline
                        else "1 (baseline)" if s == baseline else "-")
            line.append("" if s == baseline else f"{o['faster']} / {o['slower']} / {o['noise']}")
        if check_pass:
            p, t = check_pass.get(s, (0, 0))
            line.append(f"{p}/{t}")
        rows.append(line)
    return markdown(header, rows)


NUMBER_WORDS = {"one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9,
                "ten": 10, "eleven": 11, "twelve": 12}
_NUM = r"(\d+(?:\.\d+)?|" + "|".join(NUMBER_WORDS) + r")"
# (cells.csv column, what the description calls it, its pattern): the settings a description
# states that the cells' own values can contradict (`matrix run --threads 1` on a matrix whose
# description says "2 threads")
DESCRIBED = [("threads", "thread", re.compile(r"(?<![\w.-])" + _NUM + r"[ -]threads?\b", re.I)),
             ("frames_asked", "frame", re.compile(r"(?<![\w.-])" + _NUM + r"[ -]frames?\b", re.I)),
             ("scale", "scale", re.compile(r"(?:--scale|\bscale)[ =:]+" + _NUM + r"(?![\w.])", re.I))]


def described_value(row, col):
    """A cell's value of a DESCRIBED setting; a cell timing sampled frames ran as many frames as it
    sampled (its frames_asked is the animation they were sampled from)."""
    if col == "frames_asked" and row.get("sample_frames"):
        return float(len(row["sample_frames"].split(",")))
    return number(row.get(col))


def description_conflicts(description, cells):
    """Settings the description states and no cell ran with: ['the description says 2 threads; the
    cells ran with 1 thread', ...]. A setting stated with several values (one of them matching) is
    no conflict; a count after "first" or "last" ("the first 2 frames") is not the setting."""
    notes = []
    for col, word, pattern in DESCRIBED:
        have = {described_value(c.row, col) for c in cells} - {0.0}
        have = {v for v in have if math.isfinite(v)}
        if not have:
            continue
        stated = []
        for m in pattern.finditer(description or ""):
            before = description[:m.start()].split()[-1:] or [""]
            if before[0].lower() in ("first", "last", "every", "per"):
                continue
            t = m.group(1).lower()
            stated.append(float(NUMBER_WORDS.get(t, t)))
        if not stated or any(any(abs(v - h) <= 1e-9 * max(1.0, h) for h in have) for v in stated):
            continue
        said = ", ".join(dict.fromkeys(f"{v:g}" for v in stated))
        ran = ", ".join(f"{v:g}" for v in sorted(have))
        if col == "scale":
            notes.append(f"the matrix description says scale {said}, but the cells ran at scale {ran}")
        else:
            notes.append(f"the matrix description says {said} {word}s, but the cells ran with "
                         f"{ran} {word if have == {1.0} else word + 's'}")
    return notes


def main(argv, figure_hook=None):
    """The report of argv[1]; figure_hook(fig, path), when given, is called with every figure just
    before it is saved, laid out as it will be saved (FIGURE_HOOK), and the figure is not written
    when it returns False."""
    global FIGURE_HOOK
    if len(argv) != 2 or argv[1].startswith("-"):
        die("usage: mpmbench matrix report DIR")
    root = argv[1]
    FIGURE_HOOK = figure_hook
    CASE_TITLES.clear()
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

    CASE_TITLES.update(titles)

    md_fig, md_detail = [], []
    # ---- detail: settings
    conflicts = description_conflicts(meta.get("description") or "", cells)
    if meta.get("description"):
        md_detail.append(meta["description"] + "\n")
        if conflicts:
            md_detail.append("(Not as described: " + "; ".join(conflicts) + ". The cells' values are what ran.)\n")
    counts = {}
    for c in runs:
        counts[c.status] = counts.get(c.status, 0) + 1
    md_detail.append(f"{len(runs)} cell runs (" + ", ".join(f"{n} {s}" for s, n in sorted(counts.items())) + ")"
                     + (f", {repeat} per cell" if repeat > 1 else "") + f", {len(cases)} cases; baseline solver: "
                     f"{baseline or 'none'}. Times are over each cell's timed window (frames from first_timed_frame "
                     "on) and over the frames it finished.\n")
    sampled = sorted({(c.row.get("scene", ""), c.row.get("sample_frames", "")) for c in runs if c.row.get("sample_frames")})
    if sampled:
        md_detail.append("Sampled frames (each timed alone from a checkpoint its scene's reference run wrote, so every "
                         "solver ran on the same states; a cell's time is over these frames, its max per frame the "
                         "slowest of them): " + "; ".join(f"{s}: {f}" for s, f in sampled) + ".\n")
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
        sp_path, left_out = speedup_figure(plt, root, cases, titles, order, baseline)
        if sp_path:
            md_fig.append(f"![speedup against {baseline}]({sp_path})\n")
            md_fig.append(f"Speedup of each solver against {baseline} per case (s/frame ratio; "
                          + ("bars: the range over the repeats" if repeat > 1 else "single runs")
                          + f"; the grey band, within {NOISE_FLOOR:g}x, is not claimed; ringed: a cell ran on a busy "
                          "machine; crossed: a step did not converge)."
                          + (" Not shown: " + "; ".join(left_out) + "." if left_out else "") + "\n")
        else:
            md_fig.append(f"No speedup figure: no case in which {baseline} and another solver both ended ok with the "
                          "same timed frames.\n")
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
                rows.append([f"{s} ({setting})" if setting else s, " ".join([c.status] + c.marks()),
                             len(c.timed), spf, sp.text(), fmt(sp.per), fmt(c.outer), fmt(c.linear), fmt(lin_step),
                             c.worst, fmt(c.min_dt), fmt(c.avg_dt), fmt(c.max_residual)])
                table_rows.append({"case": title, "scene": c.row.get("scene", ""), "solver": s, "status": c.status,
                                   "timed_frames": len(c.timed), "s_per_frame": c.s_per_frame,
                                   "s_per_frame_min": c.lo, "s_per_frame_max": c.hi, "runs": len(c.runs),
                                   "speedup_total": sp.total, "speedup_max_frame": sp.per,
                                   "speedup_significant": "" if sp.significant is None else int(sp.significant),
                                   "outer_iters": c.outer, "linear_iters": c.linear, "linear_per_step": lin_step,
                                   "worst_status": c.worst, "min_dt": c.min_dt, "avg_dt": c.avg_dt,
                                   "max_residual": c.max_residual, "machine_busy": int(c.busy),
                                   "met_eps": int(c.met_eps())})
        md_detail.append(f"#### {title}\n")
        if per_scene.get(cs[0].row.get("scene", "")):
            md_detail.append(f"({per_scene[cs[0].row.get('scene', '')]})\n")
        md_detail.append(markdown(["solver", "status", "timed frames", "s/frame", f"speedup vs {baseline or '-'}",
                                   "max per-frame speedup", "outer", "linear", "linear/step", "worst status",
                                   "min dt", "avg dt", "max residual"], rows))
        rank = case_rank_line(cs, repeat)
        if rank:
            md_detail.append(f"\n{rank}\n")
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
                "linear_iters", "linear_per_step", "worst_status", "min_dt", "avg_dt", "max_residual", "machine_busy",
                "met_eps"]
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
               "legend_height": legend_height, "plain_log_axis": plain_log_axis, "mark_points": mark_points,
               "mark_legend": mark_legend, "mark_label": MARK_LABEL}
    wp_answer = accuracy.work_precision(plt, root, cells, cols, order, md_fig, md_detail, helpers)
    check_pass, rb_answer = accuracy.robustness(plt, root, md_fig, md_detail, order, helpers)
    if references:
        md_detail.append("\n### Reference runs\n")
        md_detail.append("The runs the cells' trajectories are compared with (their dt sequence is replayed):\n")
        md_detail.append(markdown(["id", "scene", "solver", "eps", "status", "frames", "s/frame"],
                                  [(c.id, c.row.get("scene", ""), c.solver, c.row.get("eps", ""), c.status,
                                    len(c.frame_time), fmt(c.s_per_frame)) for c in references]))

    # ---- the answer first
    summary, facts = solver_summary(cases, order, baseline)
    lead = [x for x in (rb_answer, wp_answer) if x]
    extra = [x for x in (stiffness_answer(ends, order), mg_answer(levels_by_case), iterations_answer(cases, order))
             if x]
    lines = answer_lines(summary, facts, order, baseline, cells, cases, repeat, dropped, compared, extra, lead,
                         conflicts)
    # the same numbers for scripts (the README's numbers are filled in from these)
    with open(os.path.join(root, "summary.json"), "w") as f:
        json.dump({"name": meta.get("name", ""), "baseline": baseline, "repeat": repeat,
                   "cells": len(runs), "cases": len(cases),
                   "status": {k: v for k, v in sorted(counts.items())},
                   "machine_busy": sum(1 for c in runs if c.busy),
                   "profile_cases": compared, "profile_left_out": len(dropped),
                   "answer": lines,
                   "solvers": {s: {"cases": summary[s]["cases"], "ended_ok_converged": summary[s]["clean"],
                                   "fastest_in": summary[s]["fastest"], "tied_fastest_in": summary[s]["tied"],
                                   "fastest_of": facts["compared"],
                                   "busy": summary[s]["busy"], "not_converged": summary[s]["unconverged"],
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
    md.append("\n(cases: cases the solver ran; fastest in: cases where its s/frame is the smallest, by more than "
              f"{noise_words(repeat)}, among the cells that ended ok with every step converged to the case's eps on a "
              "quiet machine; (tied): cases where it is the fastest or within the noise of the fastest, none clearly "
              "fastest; speedup: the baseline's s/frame over the solver's, over the cases where both cells ended ok "
              "with every step converged and the same frames on a quiet machine"
              + ("; busy / not converged: its cells run on a busy machine / with a step not converged, left out of "
                 "the other columns" if any(summary[s]["busy"] or summary[s]["unconverged"] for s in order) else "")
              + ("; faster / slower: outside the noise, ~: inside it" if baseline else "") + ".)\n")
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
