#!/usr/bin/env bash
# needs: MPM_WITH_CHOLMOD
# The report's accuracy sections (scripts/matrix_report_accuracy.py) on a
# hand-made result directory with known answers: median err_h over the
# timed steps only, the last frame's pos_rms, the time to reach err_h <=
# 1e-2 / 1e-3 / 1e-4 / 1e-6 interpolated in log-log along eps (an exact hit, "<=" at the
# loosest eps, "not reached" with the best error), the performance-profile
# ratios at matched accuracy, wp.csv, reference runs kept out of the solver
# tables, and the work-precision figure as a two-column PNG.
. "$(dirname "$0")/../common/shell_harness.sh"

d="$tmp/wp"
mkdir -p "$d/cells"
echo '{"name": "wp", "description": "hand-made", "baseline": "A", "named_axes": []}' >"$d/matrix.json"
echo "id,scene,solver,eps,scale,threads,frames_asked,first_timed_frame,error_ref,role,reference,set,solver_opts,status,exit,frames,steps,outer_iters,linear_iters,inner_iters,wall_s,timed_frames,timed_wall_s,s_per_frame,max_frame_s,max_residual,converged_fraction,worst_solve_status,particles,peak_rss_mb,startup_s,elapsed_s" >"$d/cells.csv"
# cell ID SOLVER EPS ROLE TIME ERR POS: frame 0 (not timed) takes 100 s with err_h 1 and pos_rms 9;
# frame 1 has three steps with err_h ERR/2, ERR, 5 ERR (median ERR) and takes TIME s, pos_rms POS
cell() {
  local id=$1 solver=$2 eps=$3 role=$4 t=$5 e=$6 pos=$7
  echo "$id,toy,$solver,$eps,2,2,2,1,auto,$role,$([ "$role" = cell ] && echo ref0),,,ok,0,2,4,0,0,0,0,1,0,0,0,1e-8,1.0,converged,100,10,0.1,1" >>"$d/cells.csv"
  mkdir -p "$d/cells/$id"
  python3 - "$d/cells/$id" "$t" "$e" "$pos" <<'PY'
import sys
d, t, e, pos = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
with open(f"{d}/frames.csv", "w") as f:
    f.write("scene,solver,frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,threads,inner_iters,pos_rms,pos_max,vel_rms,reason\n")
    f.write(f"toy,x,0,1,1,1,100,1e-8,converged,2,0,9,9,9,\"\"\n")
    f.write(f"toy,x,1,3,1,1,{t},1e-8,converged,2,0,{pos},{pos},{pos},\"\"\n")
with open(f"{d}/steps.csv", "w") as f:
    f.write("frame,step,wall_s,err_h,e_gap,err_v_max,ref_solver,ref_status,ref_s,reason\n")
    f.write("0,0,100,1,1,1,pn-cholmod,converged,1,\"\"\n")
    for k, x in enumerate((e / 2, e, 5 * e) if e > 0 else ()):
        f.write(f"1,{k},1,{x!r},{x * x!r},{x!r},pn-cholmod,converged,1,\"\"\n")
PY
}
cell ref0 pn-cholmod 1e-12 reference 50 0 ""
cell a1 A 0.001 cell 1 1e-3 1e-1
cell a2 A 1e-05 cell 10 1e-5 1e-3
cell a3 A 1e-07 cell 100 1e-7 1e-5
cell b1 B 0.001 cell 2 1e-5 2e-3
cell b2 B 1e-05 cell 4 1e-6 2e-4
cell b3 B 1e-07 cell 8 1e-6 2e-4
cell c1 C 0.001 cell 1 1e-2 1
cell c2 C 1e-05 cell 2 1e-3 1
cell c3 C 1e-07 cell 3 5e-4 1

"$bin" matrix report "$d" >"$tmp/out" 2>"$tmp/err"
rc=$?
check "report exit 0 ($(head -c 300 "$tmp/err"))" test $rc -eq 0
md="$d/report.md"
check "work-precision section" grep -q "^### Work precision" "$md"
check "the answer: fastest to each target" grep -q "^- Accuracy, fastest to reach a median per-step error: err_h <= 0.01: A (1 of 1 cases); err_h <= 0.001: A (1 of 1 cases); err_h <= 0.0001: B (1 of 1 cases)" "$md"
check "median err_h per eps (timed steps only)" grep -q "^| A | 0.00100 | 1.00e-05 | 1.00e-07 |$" "$md"
check "pos_rms at the last frame" grep -q "^| B | 0.00200 | 2.00e-04 | 2.00e-04 |$" "$md"
check "A: reached at the loosest eps, then interpolated 10^0.5 and 10^1.5 s" grep -q "^| A | <= 1.00 | <= 1.00 | 3.16 | 31.6 |$" "$md"
check "B: reached at the loosest eps (<=), then an exact hit" grep -q "^| B | <= 2.00 | <= 2.00 | <= 2.00 | 4.00 |$" "$md"
check "C: loosest, an exact hit at the next eps, then not reached with the best error" grep -q "^| C | <= 1.00 | 2.00 | not reached (best 5.00e-04) | not reached (best 5.00e-04) |$" "$md"
check "the reference run is no solver of the cases" bash -c "! grep -q '^| pn-cholmod |' '$md'"
check "the reference run listed apart" grep -q "^| ref0 | toy | pn-cholmod | 1e-12 | ok | 2 |" "$md"
python3 - "$d/profile_accuracy.csv" >"$tmp/prof.txt" <<'PY'
import csv, math, sys
got = {(r["target_err_h"], r["solver"]): r["ratio"] for r in csv.DictReader(open(sys.argv[1]))}
want = {("0.01", "A"): 1.0, ("0.01", "B"): 2.0, ("0.01", "C"): 1.0,
        ("0.001", "A"): 1.0, ("0.001", "B"): 2.0, ("0.001", "C"): 2.0,
        ("0.0001", "A"): 10 ** 0.5 / 2, ("0.0001", "B"): 1.0, ("0.0001", "C"): math.inf,
        ("1e-06", "A"): 10 ** 1.5 / 4, ("1e-06", "B"): 1.0, ("1e-06", "C"): math.inf}
bad = [k for k in want if k not in got or (math.isinf(want[k]) != (got[k] == "inf")) or
       (math.isfinite(want[k]) and abs(float(got[k]) - want[k]) > 1e-6)]
print("ok" if not bad and len(got) == 12 else f"got {got}")
PY
check "profile ratios at matched accuracy ($(cat "$tmp/prof.txt"))" grep -qx ok "$tmp/prof.txt"
check "the profile figure" test -s "$d/figures/profile_accuracy.png"
python3 - "$d/wp.csv" >"$tmp/wpcsv.txt" <<'PY'
import csv, sys
rows = {(r["solver"], r["eps"]): r for r in csv.DictReader(open(sys.argv[1]))}
r = rows[("A", "1e-05")]
ok = (len(rows) == 9 and float(r["err_h_median"]) == 1e-5 and float(r["e_gap_median"]) == 1e-10 and
      float(r["err_v_max"]) == 5e-5 and float(r["pos_rms_last"]) == 1e-3 and float(r["wall_s"]) == 10)
print("ok" if ok else f"got {r}")
PY
check "wp.csv ($(cat "$tmp/wpcsv.txt"))" grep -qx ok "$tmp/wpcsv.txt"
png=$(ls "$d"/figures/wp_*.png 2>/dev/null | head -1)
check "one work-precision figure" test -n "$png" -a "$(ls "$d"/figures/wp_*.png | wc -l)" -eq 1
python3 - "$png" >"$tmp/png.txt" 2>&1 <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n"
w, h = struct.unpack(">II", data[16:24])
print("ok" if w == 1420 else f"{w} x {h}")
PY
check "work-precision figure (two panels) is two columns wide ($(cat "$tmp/png.txt"))" grep -qx ok "$tmp/png.txt"

# without accuracy columns: no work-precision section (an older matrix)
mkdir -p "$tmp/plain/cells/x"
echo '{"name": "p", "named_axes": []}' >"$tmp/plain/matrix.json"
echo "id,scene,solver,eps,scale,threads,frames_asked,first_timed_frame,set,solver_opts,status,exit,frames,steps,outer_iters,linear_iters,inner_iters,wall_s,timed_frames,timed_wall_s,s_per_frame,max_frame_s,max_residual,converged_fraction,worst_solve_status,particles,peak_rss_mb,startup_s,elapsed_s" >"$tmp/plain/cells.csv"
echo "x,toy,A,1e-07,1,2,1,0,,,ok,0,1,1,1,1,0,1,1,1,1,1,1e-8,1.0,converged,10,1,0,1" >>"$tmp/plain/cells.csv"
printf 'frame,steps,outer_iters,linear_iters,wall_s,max_residual,status\n0,1,1,1,1.0,1e-8,converged\n' >"$tmp/plain/cells/x/frames.csv"
"$bin" matrix report "$tmp/plain" >/dev/null 2>"$tmp/err2"
rc=$?
check "plain report: exit 0 ($(head -c 200 "$tmp/err2"))" test $rc -eq 0
check "plain report: no work-precision section" bash -c "! grep -q 'Work precision' '$tmp/plain/report.md'"
finish
