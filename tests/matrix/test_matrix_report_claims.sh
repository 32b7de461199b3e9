#!/usr/bin/env bash
# Reports that cannot overclaim (issue 31), on hand-made copies of the
# README's tutorial (pn-pcg, pn-pcg-mf and hot on bar3 at E = 1e5 and 1e9,
# 3 frames, the first untimed; the description says "2 threads"):
#   1. quiet, with pn-pcg-mf 0.983x pn-pcg at 1e5: a win counts only outside
#      the 1.1x noise band, so that case is a tie, said as a tie, and no
#      solver is "fastest in 2 of 2";
#   2. every cell busy, run with 1 thread: the opening line says so (it
#      used to say "no case has two solvers that ended ok to compare"), the
#      description's "2 threads" comes with a note, the numbers are marked
#      busy in every table, and the figures draw them marked (ringed points,
#      "(busy)" labels) with a legend entry; no figure is empty;
#   3. a case whose baseline ran busy is drawn marked, one whose baseline
#      timed out is named under the figure; a scene given as a file gives
#      figure names without ".json"; counts of one are singular.
. "$(dirname "$0")/../common/shell_harness.sh"
py=${MPM_PYTHON:-python3}

# make DIR MODE: MODE tie | busy | mixed
make() {
  "$py" - "$1" "$2" <<'PY'
import json, os, sys
d, mode = sys.argv[1], sys.argv[2]
os.makedirs(os.path.join(d, "cells"), exist_ok=True)
desc = ("The README's five-minute tutorial: projected Newton PCG, its matrix-free variant and HOT on the "
        "varying-stiffness bar at about 12k particles; 3 frames, the first untimed, 2 threads.")
json.dump({"name": "tutorial", "description": desc, "baseline": "pn-pcg", "report_mg_levels": False,
           "named_axes": [{"name": "stiffness", "kind": "set", "values": [
               {"label": "1e+05", "settings": {"materials.middle.E": 1e5}},
               {"label": "1e+09", "settings": {"materials.middle.E": 1e9}}]}],
           "matrix": {"name": "tutorial", "description": desc}}, open(os.path.join(d, "matrix.json"), "w"))
header = ("id,scene,solver,eps,scale,threads,frames_asked,first_timed_frame,stiffness,set,solver_opts,status,exit,"
          "frames,steps,outer_iters,linear_iters,inner_iters,wall_s,timed_frames,timed_wall_s,s_per_frame,max_frame_s,"
          "max_residual,converged_fraction,worst_solve_status,particles,peak_rss_mb,startup_s,elapsed_s,cpu_s,"
          "others_cpu_s,load_start,machine_busy")
# (scene, solver, E): (s/frame, busy, status)
cells = {
    "tie": {("bar3", "pn-pcg", "1e+05"): (1.00, 0, "ok"), ("bar3", "pn-pcg-mf", "1e+05"): (1.0173, 0, "ok"),
            ("bar3", "hot", "1e+05"): (1.35, 0, "ok"), ("bar3", "pn-pcg", "1e+09"): (1.50, 0, "ok"),
            ("bar3", "pn-pcg-mf", "1e+09"): (1.30, 0, "ok"), ("bar3", "hot", "1e+09"): (0.62, 0, "ok")},
    "busy": {("bar3", "pn-pcg", "1e+05"): (2.48, 1, "ok"), ("bar3", "pn-pcg-mf", "1e+05"): (2.10, 1, "ok"),
             ("bar3", "hot", "1e+05"): (2.77, 1, "ok"), ("bar3", "pn-pcg", "1e+09"): (3.10, 1, "ok"),
             ("bar3", "pn-pcg-mf", "1e+09"): (2.90, 1, "ok"), ("bar3", "hot", "1e+09"): (1.30, 1, "ok")},
    "mixed": {("scenes/sphere-on-box.json", "pn-pcg", "1e+05"): (2.0, 1, "ok"),
              ("scenes/sphere-on-box.json", "hot", "1e+05"): (1.0, 0, "ok"),
              ("scenes/sphere-on-box.json", "pn-pcg", "1e+09"): (2.0, 0, "timeout"),
              ("scenes/sphere-on-box.json", "hot", "1e+09"): (1.0, 0, "ok")},
}[mode]
threads = 1 if mode == "busy" else 2
rows = [header]
for k, ((scene, s, e), (spf, busy, status)) in enumerate(cells.items()):
    cid = f"c{k:02d}"
    rows.append(f"{cid},{scene},{s},1e-07,3,{threads},3,1,{e},materials.middle.E={e},,{status},0,3,6,40,400,0,"
                f"{3 * spf},2,{2 * spf},{spf},{spf * 1.1},5e-8,1.000000,converged,11821,200,0.1,{3 * spf + 1},"
                f"{6 * spf},{8.0 if busy else 0.1},1.5,{busy}")
    cd = os.path.join(d, "cells", cid)
    os.makedirs(cd, exist_ok=True)
    with open(os.path.join(cd, "frames.csv"), "w") as f:
        f.write("frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,complete,reason\n")
        for fr in range(3):
            f.write(f"{fr},2,{10 + fr},{100 + fr},{spf * (2.8 if fr == 0 else 1.0):.6f},5e-8,converged,1,\"\"\n")
    with open(os.path.join(cd, "steps.csv"), "w") as f:
        f.write("frame,step,dt,status,wall_s,p2g_s,assemble_s,setup_s,solve_s,linesearch_s,g2p_s\n")
        for fr in range(3):
            w = spf * (2.8 if fr == 0 else 1.0) / 2
            for st in range(2):
                f.write(f"{fr},{st},0.002,converged,{w:.6f},{0.05 * w:.6f},{0.3 * w:.6f},{0.1 * w:.6f},"
                        f"{0.4 * w:.6f},{0.1 * w:.6f},{0.03 * w:.6f}\n")
open(os.path.join(d, "cells.csv"), "w").write("\n".join(rows) + "\n")
PY
}

# report DIR: in-process, each figure described by the hook into DIR/figures.txt
# (name, whether a ringed point is drawn, the legend's texts, empty axes)
report() {
  "$py" - "$src" "$1" <<'PY' >"$1/report.out" 2>&1
import os, sys
sys.path.insert(0, os.path.join(sys.argv[1], "scripts"))
import matrix_report
out = open(os.path.join(sys.argv[2], "figures.txt"), "w")

def hook(fig, path):
    rings = any(l.get_marker() == "o" and l.get_markerfacecolor() == "none" and l.get_markeredgecolor() == "0.45"
                for ax in fig.axes for l in ax.lines)
    legend = [t.get_text() for lg in fig.legends for t in lg.get_texts()]
    ticks = [t.get_text() for ax in fig.axes for t in ax.get_yticklabels()]
    empty = sum(1 for ax in fig.axes if not ax.lines and not ax.patches)
    print(f"{os.path.basename(path)}|rings={int(rings)}|empty={empty}|legend={';'.join(legend)}|ticks={';'.join(ticks)}",
          file=out)

sys.exit(matrix_report.main(["matrix_report.py", sys.argv[2]], figure_hook=hook))
PY
}
first() { sed -n 3p "$1/report.md"; }

# ---- 1. a tie is a tie
make "$tmp/tie" tie
report "$tmp/tie"
rc=$?
check "tie: report exit 0 ($(head -c 300 "$tmp/tie/report.out"))" test $rc -eq 0
md="$tmp/tie/report.md"
check "tie: hot wins only the case it leads by more than 1.1x" \
  grep -q "^- \*\*Fastest: hot\*\*, ahead of every other solver by more than the 1.1x noise band in 1 of 2 cases compared" "$md"
check "tie: said as a tie, with its solvers" \
  grep -q "^- Ties (the fastest within the 1.1x noise band of each other) in 1 of 2 cases: bar3 stiffness=1e+05 (pn-pcg, pn-pcg-mf)\.$" "$md"
check "tie: nobody is fastest in 2 of 2" bash -c "! grep -q 'in 2 of 2' '$md'"
check "tie: the case's own line" grep -q "^No clear fastest: pn-pcg, pn-pcg-mf within the 1.1x noise band of each other (pn-pcg 1.02x ahead of pn-pcg-mf)\.$" "$md"
check "tie: the speedup line counts faster / slower" grep -q "against pn-pcg it is 1.34x as fast (geometric mean of the s/frame ratios over 2 cases, 0.741x to 2.42x; faster in 1, slower in 1)" "$md"
check "tie: summary.json counts wins and ties apart" "$py" - "$tmp/tie/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))["solvers"]
got = {k: (v["fastest_in"], v["tied_fastest_in"], v["fastest_of"]) for k, v in s.items()}
assert got == {"pn-pcg": (0, 1, 2), "pn-pcg-mf": (0, 1, 2), "hot": (1, 0, 2)}, got
PY
check "tie: the description agrees with the cells: no note" bash -c "! grep -q 'Not as described' '$md'"

# ---- 2. every cell busy, 1 thread
make "$tmp/busy" busy
report "$tmp/busy"
rc=$?
check "busy: report exit 0 ($(head -c 300 "$tmp/busy/report.out"))" test $rc -eq 0
md="$tmp/busy/report.md"
check "busy: the opening line says what is true ($(first "$tmp/busy"))" \
  grep -q "^- \*\*No ranking\*\*: all 6 cells ran on a busy machine" "$md"
check "busy: not the false sentence" bash -c "! grep -q 'no case has two solvers that ended ok' '$md'"
check "busy: nothing claimed quiet" bash -c "! grep -q '^- All .* on a quiet machine' '$md'"
check "busy: the description's 2 threads noted against the cells' 1 thread" \
  grep -q "^(Not as described: the matrix description says 2 threads, but the cells ran with 1 thread\. " "$md"
check "busy: and in the caveats" grep -q "^- Caveats: the matrix description says 2 threads, but the cells ran with 1 thread;" "$md"
check "busy: overview s/frame marked" grep -q "^| bar3 stiffness=1e+05 | 2.48 busy | 2.10 busy | 2.77 busy |$" "$md"
check "busy: overview speedups marked" grep -q "^| bar3 stiffness=1e+09 | 1.07 ~ busy / 1.07 | 2.38 busy / 2.38 |$" "$md"
check "busy: per-case table marked" grep -q "^| hot | ok busy | 2 | 1.30 | 2.38 busy | " "$md"
check "busy: summary counts them" grep -q "^| hot | 2 | 2 | 0 | 2 / 0 | - | 0 / 0 / 0 |$" "$md"
fig="$tmp/busy/figures.txt"
check "busy: speedup figure drawn, points ringed, legend says so" grep -q "^speedup.png|rings=1|empty=0|legend=.*ringed: busy machine" "$fig"
check "busy: stiffness figure drawn with its points ringed (not an empty panel)" grep -q "^stiffness_00_bar3.png|rings=1|empty=0|" "$fig"
check "busy: frame figures label the cells (busy)" grep -q "^frames_00_.*legend=pn-pcg (busy);pn-pcg-mf (busy);hot (busy);not timed;" "$fig"
check "busy: 'not timed' is a legend entry, not a label over the markers" bash -c "! grep -q 'not timed' '$tmp/busy/report.md'"
check "busy: no empty figure" bash -c "! grep -q 'empty=[1-9]' '$fig'"

# ---- 3. a busy baseline, a failed baseline, a scene file
make "$tmp/mixed" mixed
report "$tmp/mixed"
rc=$?
check "mixed: report exit 0 ($(head -c 300 "$tmp/mixed/report.out"))" test $rc -eq 0
md="$tmp/mixed/report.md"
check "mixed: the busy baseline's case drawn, marked" grep -q "^speedup.png|rings=1|empty=0|.*|ticks=scenes/sphere-on-box.json stiffness=1e+05$" "$tmp/mixed/figures.txt"
check "mixed: the failed baseline's case named under the figure" \
  grep -q "Not shown: scenes/sphere-on-box.json stiffness=1e+09 (pn-pcg timeout)\." "$md"
check "mixed: figure names without .json" bash -c "ls '$tmp/mixed/figures' | grep -q '^frames_00_sphere-on-box_stiffness_1e_05.png$' && ! ls '$tmp/mixed/figures' | grep -q json"
check "mixed: singular counts ('1 cell run', no '1 cases')" bash -c "grep -q '; 1 cell run on a busy machine' '$md' && ! cat '$tmp'/*/report.md | grep -qE '(^|[^0-9.])1 (cases|cells|speedups|cell runs|threads|solvers)'"

finish
