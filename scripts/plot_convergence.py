#!/usr/bin/env python3
"""Convergence plot: scaled CN residual (log scale) against run time, one
curve per run, as in the HOT paper's run-time-vs-error plots (Figs. 16, 17).

usage: scripts/plot_convergence.py [--frame F] [--step S | --all-steps]
           [--x time|iter] [--out FILE.png] [--title TEXT]
           [--labels A,B,...] [--size WxH] [--keep DIR] RUN ...

RUN is an `mpmbench run --history` output directory (iters.csv, and run.json
for the solver name, eps and overrides) or an iters.csv file.

  --frame F, --step S  the timestep plotted (default frame 0, step 0);
  --all-steps          every step of frame F one after another: the time axis
                       is solver time summed over the frame's steps (each
                       step's elapsed_s counts from the start of its solve, so
                       P2G/G2P between steps are not included) and step
                       boundaries are marked on each curve;
  --x iter             outer iterations instead of seconds on the x axis;
  --labels             curve labels (default: the solver, plus what differs
                       between the runs: overrides, or the directory name);
  --keep DIR           keep the gnuplot script and data files in DIR.

The tolerance eps (from run.json, default 1e-7) is drawn as a dashed line:
a solve has converged when its residual is below it.

Needs gnuplot (Debian package gnuplot-nox: apt-get install gnuplot-nox);
scripts/setup.sh does not install it, since nothing else needs it. Python 3
standard library otherwise. Exit status: 0, 2 for bad input (no data for the
chosen step, no gnuplot), 1 if gnuplot fails.
"""
import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile


def fail(msg, status=2):
    print(f"plot_convergence: {msg}", file=sys.stderr)
    sys.exit(status)


def load(path):
    if os.path.isdir(path):
        d, iters = path, os.path.join(path, "iters.csv")
    else:
        d, iters = os.path.dirname(path) or ".", path
    if not os.path.isfile(iters):
        fail(f"{iters}: not found (run mpmbench with --history)")
    meta = {}
    try:
        with open(os.path.join(d, "run.json")) as f:
            meta = json.load(f)
    except (OSError, ValueError):
        pass
    rows = []
    with open(iters, newline="") as f:
        for r in csv.DictReader(f):
            try:
                rows.append((int(r["frame"]), int(r["step"]), int(r["iter"]), float(r["elapsed_s"]),
                             float(r["residual"])))
            except (KeyError, TypeError, ValueError):
                fail(f"{iters}: bad row {r}")
    name = os.path.basename(os.path.normpath(d))
    return {"path": d, "name": name, "meta": meta, "rows": rows}


def select(run, frame, step, all_steps, x_iter):
    """Points (x, residual) and step-start markers of one run."""
    rows = [r for r in run["rows"] if r[0] == frame and (all_steps or r[1] == step)]
    rows.sort(key=lambda r: (r[1], r[2]))
    pts, marks = [], []
    offset_t, offset_i, cur_step, last_t, last_i = 0.0, 0, None, 0.0, 0
    for fr, st, it, t, res in rows:
        if st != cur_step:
            if cur_step is not None:
                offset_t += last_t
                offset_i += last_i + 1
            cur_step = st
            marks.append(len(pts))
        last_t, last_i = t, it
        x = offset_i + it if x_iter else offset_t + t
        if res > 0 and math.isfinite(res):
            pts.append((x, res))
    return pts, [m for m in marks if m < len(pts)]


def default_labels(runs):
    solvers = [r["meta"].get("solver") or r["name"] for r in runs]
    labels = list(solvers)
    if len(set(solvers)) < len(solvers):
        ovs = [r["meta"].get("overrides") or {} for r in runs]
        keys = sorted({k for o in ovs for k in o})
        varying = [k for k in keys if len({str(o.get(k, "")) for o in ovs}) > 1]
        for i, r in enumerate(runs):
            extra = ", ".join(f"{k.split('.')[-1]}={ovs[i].get(k, '')}" for k in varying) if varying else r["name"]
            labels[i] = f"{solvers[i]} ({extra})"
    return labels


def gp_quote(s):
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", metavar="RUN")
    ap.add_argument("--frame", type=int, default=0)
    ap.add_argument("--step", type=int, default=0)
    ap.add_argument("--all-steps", action="store_true")
    ap.add_argument("--x", choices=["time", "iter"], default="time")
    ap.add_argument("--out", default="convergence.png")
    ap.add_argument("--title")
    ap.add_argument("--labels")
    ap.add_argument("--size", default="900x600")
    ap.add_argument("--keep", metavar="DIR")
    a = ap.parse_args(argv)
    try:
        width, height = (int(v) for v in a.size.lower().split("x"))
        if width < 100 or height < 100:
            raise ValueError
    except ValueError:
        fail(f"--size '{a.size}': expected WxH, at least 100x100")
    gnuplot = shutil.which("gnuplot")
    if not gnuplot:
        fail("gnuplot not found (Debian package gnuplot-nox: apt-get install gnuplot-nox)")

    runs = [load(p) for p in a.runs]
    labels = default_labels(runs)
    if a.labels:
        given = a.labels.split(",")
        if len(given) != len(runs):
            fail(f"--labels: {len(given)} labels for {len(runs)} runs")
        labels = given
    curves = []
    for run, label in zip(runs, labels):
        pts, marks = select(run, a.frame, a.step, a.all_steps, a.x == "iter")
        if not pts:
            print(f"plot_convergence: warning: {run['path']}: no iterations for frame {a.frame}"
                  + ("" if a.all_steps else f" step {a.step}"), file=sys.stderr)
            continue
        curves.append((label, pts, marks))
    if not curves:
        fail(f"no run has data for frame {a.frame}" + ("" if a.all_steps else f" step {a.step}"))

    eps_values = {float(r["meta"]["eps"]) for r in runs if "eps" in r["meta"]}
    eps = min(eps_values) if eps_values else 1e-7
    if a.title:
        title = a.title
    else:
        metas = [r["meta"] for r in runs]
        scene = ", ".join(sorted({m.get("scene", "?") for m in metas}))
        where = f"frame {a.frame}, all steps" if a.all_steps else f"frame {a.frame}, step {a.step}"
        ovs = [m.get("overrides") or {} for m in metas]
        common = {k: v for k, v in ovs[0].items() if all(o.get(k) == v for o in ovs)} if ovs else {}
        extra = "".join(f", {k.split('.')[-1]}={v}" for k, v in sorted(common.items()))
        title = f"{scene}: {where}{extra}"

    work = a.keep or tempfile.mkdtemp(prefix="plot_convergence.")
    os.makedirs(work, exist_ok=True)
    try:
        plots = []
        for k, (label, pts, marks) in enumerate(curves):
            data = os.path.join(work, f"curve{k}.dat")
            with open(data, "w") as f:
                f.write(f"# {label}\n# x residual\n")
                starts = set(marks[1:])
                for i, (x, r) in enumerate(pts):
                    if i in starts:  # a blank line: gnuplot does not join steps
                        f.write("\n")
                    f.write(f"{x:.9g} {r:.9g}\n")
                if len(marks) > 1:  # second block: step starts
                    f.write("\n\n")
                    for m in marks:
                        f.write(f"{pts[m][0]:.9g} {pts[m][1]:.9g}\n")
            plots.append(f"{gp_quote(data)} index 0 using 1:2 with linespoints ls {k + 1} title {gp_quote(label)}")
            if len(marks) > 1:
                plots.append(f"{gp_quote(data)} index 1 using 1:2 with points ls {k + 1} pt 6 ps 1.8 notitle")
        xs = [x for _, pts, _ in curves for x, _ in pts]
        ys = [r for _, pts, _ in curves for _, r in pts] + [eps]
        ylo = 10 ** math.floor(math.log10(min(ys)) - 0.2)
        yhi = 10 ** math.ceil(math.log10(max(ys)) + 0.2)
        plots.append(f"{eps:.6g} with lines dt 2 lc rgb '#555555' lw 1.5 title {gp_quote(f'eps = {eps:.0e}')}")
        colors = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#17becf", "#e377c2", "#8c564b",
                  "#bcbd22", "#7f7f7f"]
        styles = "\n".join(f"set style line {k + 1} lc rgb '{colors[k % len(colors)]}' lw 2 pt {[7, 5, 9, 13, 11][k % 5]} ps 0.9"
                           for k in range(len(curves)))
        terminal = "pngcairo enhanced font 'sans,11'"
        probe = subprocess.run([gnuplot, "-e", "set terminal pngcairo"], capture_output=True, text=True)
        if probe.returncode != 0 or probe.stderr.strip():
            terminal = "png"
        xlabel = "outer iteration" if a.x == "iter" else (
            "solver time summed over the frame's steps [s]" if a.all_steps else "time since the start of the solve [s]")
        plot_list = ", \\\n     ".join(plots)
        script = f"""set terminal {terminal} size {width},{height}
set output {gp_quote(os.path.abspath(a.out))}
set title {gp_quote(title)} noenhanced
set logscale y
set format y "10^{{%L}}"
set yrange [{ylo:.3g}:{yhi:.3g}]
set xrange [0:{max(xs) * 1.04 if max(xs) > 0 else 1:.6g}]
set xlabel {gp_quote(xlabel)}
set ylabel "scaled CN residual"
set grid xtics ytics mytics lc rgb '#dddddd'
set key top right box opaque noenhanced
{styles}
plot {plot_list}
"""
        gp = os.path.join(work, "plot.gp")
        with open(gp, "w") as f:
            f.write(script)
        res = subprocess.run([gnuplot, gp], capture_output=True, text=True)
        if res.returncode != 0:
            fail(f"gnuplot failed: {res.stderr.strip()}", 1)
        if res.stderr.strip():
            print(res.stderr.strip(), file=sys.stderr)
    finally:
        if not a.keep:
            shutil.rmtree(work, ignore_errors=True)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
