#!/usr/bin/env bash
# The figures of the committed reports fit their canvas (issue 31). For every
# study under results/ whose folder has cells.csv and report.md, the report
# is regenerated from the committed CSV files into a scratch folder (symbolic
# links to the inputs), in one Python process, and every figure is checked
# just before it would be saved (matrix_report.main's figure_hook, which
# receives the figure laid out as savefig lays it out), from matplotlib's own
# extents (the renderer's bounding box of every text artist):
#   * every text (titles, labels, tick labels, legend entries, annotations)
#     lies inside the canvas;
#   * no two drawn tick labels of one axis overlap;
#   * no axes is empty: each draws data (a line, patch or collection in data
#     coordinates with a point inside its view limits);
# and the regenerated report.md, report.csv and summary.json are the
# committed ones (a report is regenerated when the script changes; the
# status line scripts/fill_numbers.py puts first on a stale study's page is
# not the report's).
# The figures are checked, not written (PNG and SVG output would triple the
# time): all ~340 figures of the 21 studies take about a minute of CPU, spread
# over two processes (about 30 s on an idle 2-core machine).
# First the checker must catch a deliberately broken figure: a title wider
# than the canvas, overlapping tick labels, an empty panel.
# REPORT_FIGURES_ONLY="stiffness scenes-bench" limits it to those studies.
. "$(dirname "$0")/../common/shell_harness.sh"

src=$(cd "$src" && pwd)
py=${MPM_PYTHON:-python3}
studies=${REPORT_FIGURES_ONLY:-$(cd "$src/results" && for d in */; do
  [ -f "$d/cells.csv" ] && [ -f "$d/report.md" ] && echo "${d%/}"; done)}
check "found the committed reports" test -n "$studies"

# the inputs of each report, linked; its outputs are written in the scratch folder
for s in $studies; do
  mkdir -p "$tmp/$s"
  for f in "$src/results/$s"/*; do
    case "$(basename "$f")" in
    report.md | report.csv | summary.json | profile.csv | profile_accuracy.csv | wp.csv | figures) ;;
    *) ln -s "$f" "$tmp/$s/" ;;
    esac
  done
done

# two processes (two cores), the studies shared out by size, largest first, to the lighter one
set -- $(for s in $studies; do echo "$(du -sk "$src/results/$s" | cut -f1) $s"; done | sort -rn |
  awk '{ if (a <= b) { a += $1; A = A " " $2 } else { b += $1; B = B " " $2 } } END { print A ","; print B }')
half1=$(echo "$*" | cut -d, -f1)
half2=$(echo "$*" | cut -d, -f2)
cat >"$tmp/check.py" <<'PY'
import filecmp
import io
import math
import os
import sys
import time
from contextlib import redirect_stdout

src, tmp, studies = sys.argv[1], sys.argv[2], sys.argv[3:]
sys.path.insert(0, os.path.join(src, "scripts"))
import matplotlib  # noqa: E402
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.text import Text  # noqa: E402
import matrix_report  # noqa: E402

TOL = 0.5  # pixels


def drawn_tick_labels(axis):
    """The tick labels the axis draws (those of ticks inside its view interval)."""
    ticks = axis._update_ticks() if hasattr(axis, "_update_ticks") else axis.get_major_ticks()
    return [t for tick in ticks for t in (tick.label1, tick.label2) if t.get_visible() and t.get_text()]


def has_data(ax):
    """A line, patch or collection in the axes' data coordinates with a point inside the view."""
    (x0, x1), (y0, y1) = sorted(ax.get_xlim()), sorted(ax.get_ylim())
    inside = lambda x, y: x0 <= x <= x1 and y0 <= y <= y1
    for a in ax.lines + ax.patches + ax.collections:
        if not a.get_visible() or not a.get_transform().contains_branch(ax.transData):
            continue
        if hasattr(a, "get_xydata"):
            pts = a.get_xydata()
        elif hasattr(a, "get_offsets") and len(a.get_offsets()):
            pts = a.get_offsets()
        elif hasattr(a, "get_bbox"):
            b = a.get_bbox()
            if b.width == 0 and b.height == 0:
                continue
            pts = [((b.x0 + b.x1) / 2, (b.y0 + b.y1) / 2)]
        else:
            continue
        if any(math.isfinite(x) and math.isfinite(y) and inside(x, y) for x, y in pts):
            return True
    return False


def problems(fig, name):
    """What is wrong with a laid-out figure, one line each."""
    if fig.stale:  # laid out as savefig will lay it out (matrix_report.fit_texts may have drawn it)
        fig.canvas.draw()
    r = fig.canvas.get_renderer()
    w, h = fig.bbox.width, fig.bbox.height
    out = []
    tick_ids, ticks = set(), []
    for k, ax in enumerate(fig.axes):
        if ax.get_visible() and not has_data(ax):
            out.append(f"{name}: axes {k} ('{ax.get_title() or ax.get_xlabel()}') draws no data")
        for axis_name, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                tick_ids.update((id(tick.label1), id(tick.label2)))
            labels = drawn_tick_labels(axis)
            ticks += labels
            boxes = [(t.get_text(), t.get_window_extent(r)) for t in labels]
            for i in range(len(boxes)):
                for j in range(i + 1, len(boxes)):
                    (ta, a), (tb, b) = boxes[i], boxes[j]
                    if min(a.x1, b.x1) - max(a.x0, b.x0) > TOL and min(a.y1, b.y1) - max(a.y0, b.y0) > TOL:
                        out.append(f"{name}: axes {k}: {axis_name} tick labels '{ta}' and '{tb}' overlap")
    texts = [t for t in fig.findobj(Text) if id(t) not in tick_ids] + ticks
    for t in texts:
        if not t.get_visible() or not t.get_text().strip():
            continue
        b = t.get_window_extent(r)
        if b.x0 < -TOL or b.y0 < -TOL or b.x1 > w + TOL or b.y1 > h + TOL:
            out.append(f"{name}: text '{t.get_text()[:50]}' reaches outside the canvas "
                       f"({b.x0:.0f}..{b.x1:.0f} x {b.y0:.0f}..{b.y1:.0f} of {w:.0f} x {h:.0f} px)")
    return out


# the checker must catch what it is for
matrix_report.style.apply(matplotlib)
fig, ax = plt.subplots(figsize=(3.5, 2.6))
ax.plot([1, 2], [1, 2])
ax.set_title("a title far wider than the canvas of a one-column figure can hold, cut at both ends")
ax.set_xticks([1, 1.01, 2])
ax.set_xticklabels(["one", "one and a bit", "two"])
fig.add_subplot(2, 2, 4)  # an empty panel
found = problems(fig, "broken")
plt.close(fig)
for want in ("reaches outside the canvas", "overlap", "draws no data"):
    print(("ok" if any(want in x for x in found) else "MISSED") + f" broken figure: {want}")

n_fig = 0
for study in studies:
    found = []

    def hook(fig, path):
        global n_fig
        n_fig += 1
        found.extend(problems(fig, f"{study}/{os.path.basename(path)}"))
        return False  # checked, not written

    t0 = time.time()
    d = os.path.join(tmp, study)
    try:
        with redirect_stdout(io.StringIO()):
            matrix_report.main(["matrix_report.py", d], figure_hook=hook)
    except SystemExit as e:
        found.append(f"{study}: the report exited with {e.code}")
    plt.close("all")
    for f in ("report.md", "report.csv", "summary.json"):
        a, b = os.path.join(d, f), os.path.join(src, "results", study, f)
        same = os.path.exists(a) and filecmp.cmp(a, b, shallow=False)
        if not same and f == "report.md" and os.path.exists(a):
            # the committed page may open with its study's status line, which
            # scripts/fill_numbers.py puts there, not the report
            committed = open(b).read()
            if committed.startswith("> <!-- s:"):
                committed = committed.split("\n", 1)[1].lstrip("\n")
            same = open(a).read() == committed
        if not same:
            found.append(f"{study}/{f}: differs from the committed one (regenerate: mpmbench matrix report "
                         f"results/{study})")
    print(("FAIL " if found else "ok ") + f"{study} ({time.time() - t0:.1f} s)")
    for x in found:
        print("  " + x)
print(f"figures checked: {n_fig}")
PY
"$py" "$tmp/check.py" "$src" "$tmp" $half1 >"$tmp/result1.txt" 2>&1 &
pid=$!
"$py" "$tmp/check.py" "$src" "$tmp" $half2 >"$tmp/result2.txt" 2>&1
rc2=$?
wait $pid
rc1=$?
check "the checkers ran (exit $rc1, $rc2)" test $rc1 -eq 0 -a $rc2 -eq 0
# the broken-figure lines once
cat "$tmp/result1.txt" <(grep -v "broken figure" "$tmp/result2.txt") >"$tmp/result.txt"
while read -r line; do
  case "$line" in
  ok*) checks=$((checks + 1)) ;;
  FAIL* | MISSED*)
    checks=$((checks + 1))
    fails=$((fails + 1))
    echo "$line"
    ;;
  *) echo "$line" ;;
  esac
done <"$tmp/result.txt"
finish
