"""The accuracy and robustness sections of `mpmbench matrix report` (imported
by matrix_report.py; SPEC 11, issue 10).

Work precision, for cells whose steps.csv has err_h (run with error_ref) or
whose frames.csv has pos_rms (run against a reference run):

  * per cell: the median err_h, e_gap and the largest err_v_max over the
    steps of the timed window, and pos_rms / pos_max / vel_rms at the last
    frame; the time is the timed window's wall seconds (which exclude the
    reference solves: they are ref_s);
  * a work-precision case is a case without its eps: one line per solver
    through its cells in eps order (cells that did not end ok are left out);
  * figures/wp_NN_CASE.png: wall time against median err_h (each point
    labelled by its eps, the targets inside the data's range as labelled
    lines) and against the last frame's pos_rms, log-log, one line per
    solver, a cell run on a busy machine ringed and one with a step not
    converged crossed; a panel without data (no error_ref: no err_h; no
    reference run: no pos_rms) is left out and the report says why;
  * "time to reach err_h <= 1e-2 / 1e-3 / 1e-4 / 1e-6": along the solver's eps sequence
    (loosest first), the first cell whose median err_h is at or below the
    target, the time interpolated linearly in log(err_h)-log(time) between
    it and the cell before it; "<= t" when the loosest eps already reaches
    the target (it may be reached sooner), "not reached (best E)" when no
    eps does;
  * performance profiles at matched accuracy: each (case, target) is a
    problem, a solver's cost its time to reach the target (not reached: never
    within any factor); figures/profile_accuracy.png, profile_accuracy.csv;
  * wp.csv: one row per cell with these numbers.

Robustness, when DIR/check.csv exists (`matrix run --check`): a case x solver
grid of pass / FAIL, the share of cases each solver passed, the reasons of
every failing cell, and figures/robustness.png, the grid as a table with the
status word in each cell.

Both return a line for the report's answer.
"""
import csv
import math
import os
import statistics

# 1e-2 and 1e-3 too: at the paper's eps = 1e-7 the measured median err_h is
# 1e-4 ... 6e-2 (results/work-precision), so 1e-4 / 1e-6 alone leave most
# solvers "not reached"
TARGETS = (1e-2, 1e-3, 1e-4, 1e-6)


def _num(s):
    try:
        v = float(s)
    except (TypeError, ValueError):
        return float("nan")
    return v


def _finite(xs):
    return [x for x in xs if math.isfinite(x)]


def _read(path):
    try:
        with open(path, newline="") as f:
            return list(csv.DictReader(f))
    except OSError:
        return None


def cell_accuracy(cell):
    """Sets the accuracy numbers of a report Cell from its steps.csv and frames.csv."""
    steps = _read(os.path.join(cell.dir, "steps.csv")) or []
    timed = [s for s in steps if _num(s.get("frame")) >= cell.first]
    err = _finite([_num(s.get("err_h")) for s in timed])
    gap = _finite([_num(s.get("e_gap")) for s in timed])
    vmax = _finite([_num(s.get("err_v_max")) for s in timed])
    cell.err_h = statistics.median(err) if err else float("nan")
    cell.e_gap = statistics.median(gap) if gap else float("nan")
    cell.err_v_max = max(vmax) if vmax else float("nan")
    frames = _read(os.path.join(cell.dir, "frames.csv")) or []
    last = max(frames, key=lambda f: _num(f.get("frame")), default={}) if frames else {}
    cell.pos_rms = _num(last.get("pos_rms"))
    cell.pos_max = _num(last.get("pos_max"))
    cell.vel_rms = _num(last.get("vel_rms"))
    cell.has_accuracy = bool(err) or math.isfinite(cell.pos_rms)


def time_to_reach(points, target):
    """points: [(eps, err, time)] of one solver; returns (time, mark): mark "" interpolated
    or exact, "<=" reached at the loosest eps, None when not reached (time = best err)."""
    pts = sorted((p for p in points if math.isfinite(p[1]) and math.isfinite(p[2]) and p[2] > 0),
                 key=lambda p: -p[0])
    if not pts:
        return None, None
    for k, (eps, err, t) in enumerate(pts):
        if err > target:
            continue
        if k == 0:
            return t, "<="
        e0, t0 = pts[k - 1][1], pts[k - 1][2]
        if err <= 0 or e0 <= 0 or e0 == err:
            return t, ""
        frac = (math.log(target) - math.log(e0)) / (math.log(err) - math.log(e0))
        return math.exp(math.log(t0) + frac * (math.log(t) - math.log(t0))), ""
    return min(p[1] for p in pts), None


def _fmt_time(t, mark, fmt):
    if mark is None:
        return f"not reached (best {fmt(t)})" if t is not None else "-"
    return f"{mark} {fmt(t)}".strip()


def _profile(plt, root, problems, order, md, helpers):
    """problems: {(case, target): {solver: time or inf}}; Dolan & More at matched accuracy."""
    ratios = {s: [] for s in order}
    rows = []
    for (case, target), times in problems.items():
        finite = [t for t in times.values() if math.isfinite(t)]
        best = min(finite) if finite else math.inf
        for s in order:
            if s not in times:
                continue
            r = times[s] / best if math.isfinite(best) and best > 0 else math.inf
            ratios[s].append(r)
            rows.append((case, target, s, r))
    with open(os.path.join(root, "profile_accuracy.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "target_err_h", "solver", "ratio"])
        for case, target, s, r in rows:
            w.writerow([case, f"{target:g}", s, f"{r:.6f}" if math.isfinite(r) else "inf"])
    fig, ax = helpers["profile_figure"](plt, ratios, order)
    if fig is None:
        return
    ax.set_xlabel("tau (time to the target within tau x the best)")
    ax.set_ylabel("share of problems")
    ax.set_title(f"At matched accuracy, {len(problems)} problems")
    path = helpers["save"](fig, root, "profile_accuracy.png")
    plt.close(fig)
    md.append(f"![performance profile at matched accuracy]({path})\n")
    md.append("Performance profile at matched accuracy: each (case, target err_h <= "
              + ", ".join(f"{t:g}" for t in TARGETS) + ") is a problem; a solver's cost is its time to reach the "
              "target (not reached: never within any factor).\n")


def _per_eps_table(lines, eps_values, value, fmt, markdown):
    """One row per solver, one column per eps: value(cell), "-" where the solver has no cell."""
    rows = []
    for s, pts in lines.items():
        by_eps = {_num(c.row.get("eps")): c for c in pts}
        rows.append([s] + [fmt(value(by_eps[e])) if e in by_eps else "-" for e in eps_values])
    return markdown(["solver"] + [f"eps {e:g}" for e in eps_values], rows)


def work_precision(plt, root, cells, cols, order, md_fig, md, helpers):
    """The work-precision section (see the module's docstring): per-case tables and figures into
    md (the detail), the profile at matched accuracy into md_fig; returns the answer line."""
    fmt, markdown, slug, save, new_figure, case_title, varying = (
        helpers["fmt"], helpers["markdown"], helpers["slug"], helpers["save"], helpers["new_figure"],
        helpers["case_title"], helpers["varying"])
    style, value_key = helpers["style"], helpers["value_key"]
    for c in cells:
        cell_accuracy(c)
    acc = [c for c in cells if c.has_accuracy]
    if not acc:
        return
    rest = [k for k in cols if k != "eps"]
    groups = {}
    for c in acc:
        groups.setdefault(tuple(c.row.get(k, "") for k in rest), []).append(c)
    groups = dict(sorted(groups.items(), key=lambda kv: tuple(value_key(v) for v in kv[0])))
    show = varying(acc, rest)
    has_trajectory = any(math.isfinite(c.pos_rms) for c in acc)
    md.append("\n### Work precision\n")
    md.append("Per-step error err_h = ||dv - dv*||_H / ||dv* - dv0||_H against the reference solve of the same "
              "step problem (median over the timed steps), the last frame's particle position error pos_rms (in "
              "dx) against the reference run, and the timed wall time, which excludes the reference solves "
              "(their time is ref_s). Cells that did not end ok are left out.\n")
    wp_rows, problems = [], {}
    has_err = any(math.isfinite(c.err_h) for c in acc)
    if not has_err:
        md.append("(No err_h panel in the figures: no cell ran with error_ref, so the per-step error was not "
                  "measured.)\n")
    if not has_trajectory:
        md.append("(No trajectory panel in the figures: the matrix has no reference run, so pos_rms was not "
                  "measured.)\n")
    for i, (key, cs) in enumerate(groups.items()):
        title = case_title(key, rest, show)
        lines = {}
        for s in order:
            pts = sorted((c for c in cs if c.solver == s and c.status == "ok"), key=lambda c: -_num(c.row.get("eps")))
            if pts:
                lines[s] = pts
        for c in cs:
            wp_rows.append([title, c.solver, c.row.get("eps", ""), c.status, c.timed_wall, c.err_h, c.e_gap,
                            c.err_v_max, c.pos_rms, c.pos_max, c.vel_rms])
        if not lines:
            continue
        md.append(f"#### {title}\n")
        eps_values = sorted({_num(c.row.get("eps")) for c in cs}, reverse=True)
        md.append("Median err_h per eps:\n")
        md.append(_per_eps_table(lines, eps_values, lambda c: c.err_h, fmt, markdown))
        if any(math.isfinite(c.pos_rms) for c in cs):
            md.append("\nLast frame's pos_rms (dx) per eps:\n")
            md.append(_per_eps_table(lines, eps_values, lambda c: c.pos_rms, fmt, markdown))
        rows = []
        for s, pts in lines.items():
            line = [s]
            for target in TARGETS:
                t, mark = time_to_reach([(_num(c.row.get("eps")), c.err_h, c.timed_wall) for c in pts], target)
                line.append(_fmt_time(t, mark, fmt))
                problems.setdefault((title, target), {})[s] = t if mark is not None else math.inf
            rows.append(line)
        md.append("\nWall seconds (timed window) to reach a median err_h, interpolated in log-log along eps:\n")
        md.append(markdown(["solver"] + [f"err_h <= {t:g}" for t in TARGETS], rows))
        # a panel per measure the cells have: median err_h (error_ref), pos_rms (a reference run)
        err = {s: [(c.err_h, c.timed_wall, c) for c in pts if math.isfinite(c.err_h) and c.err_h > 0]
               for s, pts in lines.items()}
        pos = {s: [(c.pos_rms, c.timed_wall, c) for c in pts if math.isfinite(c.pos_rms) and c.pos_rms > 0]
               for s, pts in lines.items()}
        shown = [(d, lab) for d, lab in ((err, "median err_h per step"), (pos, "pos_rms at the last frame [dx]"))
                 if any(d.values())]
        if not shown:
            md.append("\n(No work-precision figure: no cell has a positive err_h or pos_rms.)\n")
            continue
        if has_err and has_trajectory and len(shown) < 2:
            md.append("\n(No err_h panel: no cell of this case has a positive median err_h.)\n" if shown[0][0] is pos
                      else "\n(No pos_rms panel: no cell of this case has a positive pos_rms.)\n")
        panels = len(shown)
        names = list(lines)
        drawn = {m for d, _ in shown for e in d.values() for _, _, c in e for m in c.marks()}
        leg = names + [helpers["mark_label"][m] for m in drawn]
        width = (style.TWO_COLUMNS if panels == 2 else style.ONE_COLUMN)[0]
        fig, axes = new_figure(plt, panels, height=(style.TWO_COLUMNS[1] if panels == 2 else 2.9)
                               + helpers["legend_height"](len(leg), width, leg))
        axes = list(axes) if panels == 2 else [axes]
        labels = []
        for a, (d, lab) in zip(axes, shown):
            marks = []
            for s in names:
                kw = style.line_kwargs(s, names, ms=3.5)
                if d[s]:
                    a.plot([x for x, _, _ in d[s]], [y for _, y, _ in d[s]], **kw)
                    marks += [(x, y, c.marks()) for x, y, c in d[s]]
                    if d is err:
                        labels.append((kw["color"], d[s]))
            helpers["mark_points"](a, marks)
            a.set_xscale("log")
            a.set_yscale("log")
            a.set_xlabel(lab)
            a.set_ylabel("wall seconds (timed window)")
            helpers["plain_log_axis"](a, "x")
            helpers["plain_log_axis"](a, "y")
            if d is err:
                lo, hi = sorted(a.get_xlim())
                for target in TARGETS:
                    if not lo * 1.2 <= target <= hi / 1.2:  # inside, clear of the axes' ends
                        continue
                    a.axvline(target, ls="--", color="0.6", lw=0.7)
                    a.annotate(f"{target:.0e}".replace("e-0", "e-"), xy=(target, 1.0),
                               xycoords=("data", "axes fraction"), ha="center", va="bottom",
                               fontsize=style.FONT_PT - 2, color="0.4")
                _label_eps(fig, a, labels, style.FONT_PT - 2.5)
        helpers["legend_outside"](fig, axes[0], extra=helpers["mark_legend"](drawn))
        fig.suptitle(f"Work precision: {title}", fontsize=style.FONT_PT + 1)
        path = save(fig, root, f"wp_{i:02d}_{slug(title)}.png")
        plt.close(fig)
        md.append(f"\n![work precision, {title}]({path})\n")
    with open(os.path.join(root, "wp.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "solver", "eps", "status", "wall_s", "err_h_median", "e_gap_median", "err_v_max",
                    "pos_rms_last", "pos_max_last", "vel_rms_last"])
        for r in wp_rows:
            w.writerow([f"{x:.9g}" if isinstance(x, float) and math.isfinite(x) else
                        "" if isinstance(x, float) else x for x in r])
    if problems:
        _profile(plt, root, problems, order, md_fig, helpers)
    return _wp_answer(problems, fmt)


def _label_eps(fig, ax, lines, size):
    """Each point labelled by its eps, in the line's colour, leaving out a label that would
    overlap one already placed (points nearer than about one label in display space)."""
    fig.canvas.draw()  # the final limits, so data map to display coordinates
    placed = []
    for colour, pts in lines:
        for x, y, c in pts:
            px, py = ax.transData.transform((x, y))
            if any(abs(px - qx) < 26 and abs(py - qy) < 9 for qx, qy in placed):
                continue
            placed.append((px, py))
            ax.annotate(f"{_num(c.row.get('eps')):.0e}".replace("e-0", "e-"), (x, y), textcoords="offset points",
                        xytext=(3, 2), fontsize=size, color=colour)


def _wp_answer(problems, fmt):
    """'Accuracy: fastest to err_h <= T: S (k of n cases)' for every target some solver reached."""
    parts = []
    for target in TARGETS:
        wins, n = {}, 0
        for (case, t), times in problems.items():
            if t != target:
                continue
            finite = {s: x for s, x in times.items() if math.isfinite(x)}
            if not finite:
                continue
            n += 1
            best = min(finite, key=finite.get)
            wins[best] = wins.get(best, 0) + 1
        if n:
            top = sorted(wins.items(), key=lambda kv: -kv[1])
            parts.append(f"err_h <= {target:g}: {top[0][0]} ({top[0][1]} of {n} cases)")
    if not parts:
        return None
    return "Accuracy, fastest to reach a median per-step error: " + "; ".join(parts) + "."


def robustness(plt, root, md_fig, md, order, helpers):
    """The pass/fail grid of DIR/check.csv (matrix run --check): the table into md (the detail),
    the grid figure into md_fig; returns ({solver: (passed, total)}, answer line) or (None, None)."""
    rows = _read(os.path.join(root, "check.csv"))
    if not rows:
        return None, None
    markdown, save, style = helpers["markdown"], helpers["save"], helpers["style"]
    fixed = {"id", "solver", "pass", "reasons"}
    keys = [k for k in rows[0] if k not in fixed]
    keys = [k for k in keys if k == "scene" or len({r.get(k, "") for r in rows}) > 1]
    grid, cases = {}, []
    def case_of(r):
        # a named axis whose value already names the scene ("case": "bar3 E_mid=1e4") is shown alone
        parts = [f"{k}={r[k]}" if not r[k].startswith(r.get("scene", "") + " ") else r[k]
                 for k in keys if k != "scene"]
        if any(not p.startswith(f"{k}=") for p, k in zip(parts, [k for k in keys if k != "scene"])):
            return " ".join(parts)
        return " ".join([r.get("scene", "")] + parts)

    for r in rows:
        case = case_of(r)
        if case not in cases:
            cases.append(case)
        grid[(case, r["solver"])] = r
    solvers = [s for s in order if any((c, s) in grid for c in cases)]
    solvers += sorted({r["solver"] for r in rows} - set(solvers))
    md.append("\n### Robustness (matrix run --check)\n")
    md.append("Pass: every step converged (residual re-checked) or reported capped / stalled / timeout / failed, no "
              "NaN or Inf in the outputs, no line search accepted an energy increase, the run ended inside its "
              "wall-clock limit and particles stayed in the domain or the run said otherwise "
              "(experiments/matrix/matrix_check.h).\n")
    word = {}
    for case in cases:
        for s in solvers:
            r = grid.get((case, s))
            word[(case, s)] = "-" if r is None else "pass" if r["pass"] == "1" else "FAIL"
    table = [[case] + [{"FAIL": "**FAIL**"}.get(word[(case, s)], word[(case, s)]) for s in solvers] for case in cases]
    passed = {s: (sum(1 for c in cases if word[(c, s)] == "pass"), sum(1 for c in cases if (c, s) in grid))
              for s in solvers}
    table.append(["**passed**"] + [f"{passed[s][0]}/{passed[s][1]}" for s in solvers])
    md.append(markdown(["case"] + solvers, table))
    fails = [r for r in rows if r["pass"] != "1"]
    if fails:
        md.append("\nFailing cells:\n")
        for r in fails:
            case = case_of(r)
            md.append(f"- {case} / {r['solver']} ({r['id']}): {r['reasons']}")
        md.append("")
    # the grid as a table-figure: one row per case, the status word in each cell
    width = min(7.1, 1.6 + 0.62 * len(solvers))
    fig, ax = plt.subplots(figsize=(width, 0.55 + 0.16 * (len(cases) + 1)))
    for i, case in enumerate(cases):
        for j, s in enumerate(solvers):
            w = word[(case, s)]
            ax.add_patch(__import__("matplotlib").patches.Rectangle((j, i), 1, 1, facecolor=style.STATUS_FILL[w],
                                                                     edgecolor="white", lw=0.8))
            ax.text(j + 0.5, i + 0.5, w, ha="center", va="center", fontsize=style.FONT_PT - 2,
                    fontweight="bold" if w == "FAIL" else "normal")
    ax.set_xlim(0, len(solvers))
    ax.set_ylim(len(cases), 0)
    ax.set_xticks([j + 0.5 for j in range(len(solvers))])
    ax.set_xticklabels(solvers, rotation=90, ha="center", va="bottom", fontsize=style.FONT_PT - 1.5)
    ax.xaxis.tick_top()
    ax.set_yticks([i + 0.5 for i in range(len(cases))])
    ax.set_yticklabels(cases, fontsize=style.FONT_PT - 1.5)
    ax.tick_params(length=0)
    ax.grid(False)
    for sp in ax.spines.values():
        sp.set_visible(False)
    total_p = sum(p for p, _ in passed.values())
    total = sum(t for _, t in passed.values())
    path = save(fig, root, "robustness.png")
    plt.close(fig)
    md_fig.append(f"![robustness grid]({path})\n")
    md_fig.append(f"Robustness (`matrix run --check`): {total_p} of {total} cells pass; one row per case, one column "
                  "per solver.\n")
    failing = sorted(((t - p, s) for s, (p, t) in passed.items() if p < t), reverse=True)
    answer = f"Robustness: {total_p} of {total} cells pass `--check`"
    answer += ("; every solver passes every case" if not failing else
               "; failing: " + ", ".join(f"{s} {n} of {passed[s][1]}" for n, s in failing))
    return passed, answer + "."
