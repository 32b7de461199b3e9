#!/usr/bin/env bash
# Regression tests of `mpmbench matrix report` for the report bugs of issue
# 19, on hand-made result directories with known answers (the format of
# older runs, where the bug came from the data, and the new columns):
#   1. a description longer than 1,024 characters is reported whole;
#   2. a frame the run's time limit cut short is no frame, and such a cell is
#      "time-limit", not "ok" (3.7 s stub: no 120 s/frame, no speedup);
#   3. the total speedup is the ratio of s/frame (cells with different frame
#      counts are not compared), and 4. the max per-frame speedup is never
#      below it;
#   5. numeric axes sort by value (1e-05 < 0.0001 < 0.001 < 0.01; 1e4 < 1e10);
#   6. frames_asked / threads 0 in cells.csv are replaced by run.json's counts;
#   7. the performance profile compares only cases where every solver met
#      the case's eps and did work, and lists the others with the reason;
#   8. repeats: the median and min-max range, a ratio inside the range ~;
#   9. a cell run on a busy machine is flagged and left out of the answer;
#  10. the report opens with its answer lines and one summary table;
#  11. a work-precision figure without reference runs has no trajectory
#      panel, and the report says why; every PNG has an SVG beside it.
. "$(dirname "$0")/../common/shell_harness.sh"

header="id,scene,solver,eps,scale,threads,frames_asked,first_timed_frame,level,set,solver_opts,status,exit,frames,steps,outer_iters,linear_iters,inner_iters,wall_s,timed_frames,timed_wall_s,s_per_frame,max_frame_s,max_residual,converged_fraction,worst_solve_status,particles,peak_rss_mb,startup_s,elapsed_s"
# cell DIR ID SCENE SOLVER EPS LEVEL STATUS MAXRES EXTRA "wall outer status [reason]"... (frames from 0)
cell() {
  local d=$1 id=$2 scene=$3 solver=$4 eps=$5 level=$6 status=$7 maxres=$8 extra=$9
  shift 9
  echo "$id,$scene,$solver,$eps,1,0,0,0,$level,,,$status,0,$#,0,0,0,,0,0,0,0,0,$maxres,1.0,converged,100,10,0.1,1$extra" >>"$d/cells.csv"
  mkdir -p "$d/cells/$id"
  echo '{"frames": 2, "threads": 2, "limits": {"max_run_seconds": 240}}' >"$d/cells/$id/run.json"
  echo "frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,reason" >"$d/cells/$id/frames.csv"
  local f=0
  for fr in "$@"; do
    set -- $fr
    local why="${4:-}"
    [ "$why" = cut ] && why="time limit --max-run-seconds 240 reached in PCG at outer iteration 8"
    echo "$f,1,$2,$2,$1,$maxres,$3,\"$why\"" >>"$d/cells/$id/frames.csv"
    f=$((f + 1))
  done
}
field() { # dir case solver column
  python3 - "$1/report.csv" "$2" "$3" "$4" <<'PY'
import csv, sys
r = [x for x in csv.DictReader(open(sys.argv[1])) if x["case"] == sys.argv[2] and x["solver"] == sys.argv[3]]
print(r[0][sys.argv[4]] if len(r) == 1 else f"{len(r)} rows")
PY
}

# ---- a study of the old format (no complete / machine_busy / repeat columns)
d="$tmp/old"
mkdir -p "$d/cells"
long=$(python3 -c 'print(" ".join(f"w{i:04d}" for i in range(400)))') # 2,399 characters
python3 - "$d/matrix.json" "$long" <<'PY'
import json, sys
json.dump({"name": "old", "description": sys.argv[2][:1023], "baseline": "base", "named_axes": [],
           "matrix": {"name": "old", "description": sys.argv[2]}}, open(sys.argv[1], "w"))
PY
echo "$header" >"$d/cells.csv"
# twist: the gast15 cell's run stopped at 240 s in frame 1 (a 3.7 s stub), cells.csv said ok
cell "$d" t1 twist base 1e-07 a ok 9e-8 "" "20 5 converged" "29 5 converged"
cell "$d" t2 twist gast15 1e-07 a ok 9e-8 "" "236.3 5 converged" "3.7 1 timeout cut"
# bar3: 'short' finished 1 of its 2 frames (another count), 'fast' both
cell "$d" b1 bar3 base 1e-07 a ok 9e-8 "" "4 5 converged" "4 5 converged"
cell "$d" b2 bar3 short 1e-07 a ok 9e-8 "" "2.5 5 converged"
cell "$d" b3 bar3 fast 1e-07 a ok 9e-8 "" "3 5 converged" "1 5 converged"
# eps sweep on drop (sorted by value), one case where a solver did no work, one where one stopped at
# another accuracy (gast15: CN residual 3.6e-6 against eps 1e-7)
for e in 0.01 0.001 0.0001 1e-05; do
  cell "$d" "d$e" drop base "$e" a ok 1e-9 "" "2 3 converged" "2 3 converged"
  cell "$d" "f$e" drop fast "$e" a ok 1e-9 "" "1 3 converged" "1 3 converged"
done
echo "frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,reason" >"$d/cells/f0.01/frames.csv"
printf '0,1,0,0,0.5,1e-9,converged,""\n1,1,0,0,0.5,1e-9,converged,""\n' >>"$d/cells/f0.01/frames.csv"
cell "$d" l1 level base 1e-07 1e10 ok 9e-8 "" "2 3 converged" "2 3 converged"
cell "$d" l2 level base 1e-07 1e4 ok 9e-8 "" "2 3 converged" "2 3 converged"
cell "$d" l3 level base 1e-07 1e11 ok 9e-8 "" "2 3 converged" "2 3 converged"
cell "$d" g1 hot-case base 1e-07 a ok 9e-8 "" "2 3 converged" "2 3 converged"
cell "$d" g2 hot-case gast15 1e-07 a ok 3.6e-6 "" "0.5 3 converged" "0.5 3 converged"

"$bin" matrix report "$d" >"$tmp/out" 2>"$tmp/err"
rc=$?
check "report exit 0 ($(head -c 300 "$tmp/err"))" test $rc -eq 0
md="$d/report.md"
check "1. the whole description (2,399 characters)" grep -q "w0399" "$md"
check "2. a run cut at its time limit is time-limit, not ok" test "$(field "$d" "twist eps=1e-07 level=a" gast15 status)" = time-limit
check "2. the cut frame is no frame: 1 timed frame, 236.3 s/frame" test "$(field "$d" "twist eps=1e-07 level=a" gast15 timed_frames),$(field "$d" "twist eps=1e-07 level=a" gast15 s_per_frame)" = "1,236.300000"
check "2. no speedup for it (was 7.80 per frame from the stub)" test "$(field "$d" "twist eps=1e-07 level=a" gast15 speedup_total),$(field "$d" "twist eps=1e-07 level=a" gast15 speedup_max_frame)" = ","
check "3. different frame counts: no speedup (totals gave 8/2 = 4)" test "$(field "$d" "bar3 eps=1e-07 level=a" short speedup_total)" = ""
check "3. total speedup = ratio of s/frame: 4 / 2 = 2" test "$(field "$d" "bar3 eps=1e-07 level=a" fast speedup_total)" = "2.000000"
check "4. max per-frame speedup 4/1 = 4" test "$(field "$d" "bar3 eps=1e-07 level=a" fast speedup_max_frame)" = "4.000000"
check "3./4. every row: total = base s/frame over s/frame, max per frame >= total" python3 - "$d/report.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
base = {r["case"]: float(r["s_per_frame"]) for r in rows if r["solver"] == "base"}
n = 0
for r in rows:
    if r["speedup_total"]:
        n += 1
        assert abs(float(r["speedup_total"]) - base[r["case"]] / float(r["s_per_frame"])) < 1e-5, r
        assert float(r["speedup_max_frame"]) >= float(r["speedup_total"]) - 1e-9, r
assert n >= 8, n
PY
python3 - "$md" >"$tmp/order.txt" <<'PY'
import sys
lines = [l for l in open(sys.argv[1]) if l.startswith("#### ")]
print(" ".join(l.split()[1] + ("/" + l.split()[2] if len(l.split()) > 2 else "") for l in lines))
PY
check "5. cases sorted by value ($(cat "$tmp/order.txt"))" grep -q "drop/eps=1e-05 drop/eps=0.0001 drop/eps=0.001 drop/eps=0.01" "$tmp/order.txt"
check "5. named axis sorted by value" python3 - "$md" <<'PY'
import sys
t = [l.split()[2] for l in open(sys.argv[1]) if l.startswith("#### level ")]
assert t == ["eps=1e-07"] * 3, t
t = [l.split()[3] for l in open(sys.argv[1]) if l.startswith("#### level ")]
assert t == ["level=1e4", "level=1e10", "level=1e11"], t
PY
check "6. threads and frames_asked from run.json, not 0" grep -q "^Same in every cell: .*threads=2, frames_asked=2" "$md"
python3 - "$d/profile.csv" >"$tmp/prof.txt" <<'PY'
import csv, sys
print(" ".join(sorted({r["case"] for r in csv.DictReader(open(sys.argv[1]))})))
PY
check "7. profile: only the cases every solver met to eps with work ($(cat "$tmp/prof.txt"))" test "$(cat "$tmp/prof.txt")" = "bar3 eps=1e-07 level=a drop eps=0.0001 level=a drop eps=0.001 level=a drop eps=1e-05 level=a"
check "7. the left-out cases listed with the reason" grep -q "^- hot-case eps=1e-07 level=a: gast15 stopped at CN residual 3.60e-06 > eps 1.00e-07" "$md"
check "7. no work named" grep -q "^- drop eps=0.01 level=a: fast did no work (0 outer iterations)" "$md"
check "7. failures named" grep -q "^- twist eps=1e-07 level=a: gast15 time-limit" "$md"
check "10. the answer first" test "$(sed -n 3p "$md" | cut -c1-13)" = "- **Fastest: "
check "10. the answer: fastest counts only cells that met eps" grep -q "^- \*\*Fastest: fast\*\*, ahead of every other solver by more than the 1.1x noise band in 5 of 5 cases compared" "$md"
check "10. then one summary table, figures, detail" python3 - "$md" <<'PY'
import sys
heads = [l.strip() for l in open(sys.argv[1]) if l.startswith("## ")]
assert heads == ["## Summary", "## Figures", "## Detail"], heads
PY
check "10. the caveats line counts the time-limit cell" grep -q "^- Caveats: 1 of 18 cells did not end ok (1 time-limit)" "$md"
check "10. single runs: ratios within 1.1x not claimed" grep -q "every cell ran once" "$md"
check "10. summary.json: the answer's numbers for scripts" python3 - "$d/summary.json" "$md" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
f = s["solvers"]["fast"]
assert (f["fastest_in"], f["fastest_of"], s["cells"], s["status"]) == (5, 5, 18, {"ok": 17, "time-limit": 1}), s
assert s["answer"][0] in open(sys.argv[2]).read(), s["answer"][0]
assert s["profile_cases"] == 4 and s["profile_left_out"] == 3, s
PY

# ---- repeats and machine load (the new columns)
d="$tmp/new"
mkdir -p "$d/cells"
echo '{"name": "new", "baseline": "base", "named_axes": [], "matrix": {"repeat": 3}}' >"$d/matrix.json"
echo "id,scene,solver,eps,scale,threads,frames_asked,first_timed_frame,repeat,set,solver_opts,status,exit,frames,steps,outer_iters,linear_iters,inner_iters,wall_s,timed_frames,timed_wall_s,s_per_frame,max_frame_s,max_residual,converged_fraction,worst_solve_status,particles,peak_rss_mb,startup_s,elapsed_s,cpu_s,others_cpu_s,load_start,machine_busy" >"$d/cells.csv"
run() { # id scene solver repeat s/frame busy
  echo "$1,$2,$3,1e-07,1,2,1,0,$4,,,ok,0,1,1,3,3,,$5,1,$5,$5,$5,9e-8,1.0,converged,100,10,0.1,1,2,$([ "$6" = 1 ] && echo 5 || echo 0),0.1,$6" >>"$d/cells.csv"
  mkdir -p "$d/cells/$1"
  printf 'frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,complete,reason\n0,1,3,3,%s,9e-8,converged,1,""\n' "$5" >"$d/cells/$1/frames.csv"
}
# a: base 2.0 2.1 1.9, fast 1.0 1.2 0.9 -> medians 2.0 / 1.0 = 2, range 1.9/1.2 .. 2.1/0.9: significant
run a1 a base 1 2.0 0; run a2 a base 2 2.1 0; run a3 a base 3 1.9 0
run a4 a fast 1 1.0 0; run a5 a fast 2 1.2 0; run a6 a fast 3 0.9 0
# b: base 2.0 2.4 1.8, fast 1.9 2.2 1.7 -> ratio 2.0/1.9 inside the spread: ~
run b1 b base 1 2.0 0; run b2 b base 2 2.4 0; run b3 b base 3 1.8 0
run b4 b fast 1 1.9 0; run b5 b fast 2 2.2 0; run b6 b fast 3 1.7 0
# c: every run of fast on a busy machine
run c1 c base 1 2.0 0; run c2 c base 2 2.0 0; run c3 c base 3 2.0 0
run c4 c fast 1 0.5 1; run c5 c fast 2 0.5 1; run c6 c fast 3 0.5 1
"$bin" matrix report "$d" >"$tmp/out" 2>"$tmp/err"
rc=$?
check "repeat report exit 0 ($(head -c 300 "$tmp/err"))" test $rc -eq 0
md="$d/report.md"
check "8. median of the repeats" test "$(field "$d" a fast s_per_frame),$(field "$d" a fast runs)" = "1.000000,3"
check "8. min-max range" test "$(field "$d" a fast s_per_frame_min),$(field "$d" a fast s_per_frame_max)" = "0.900000,1.200000"
check "8. outside the spread: significant" test "$(field "$d" a fast speedup_significant)" = 1
check "8. inside the spread: not significant" test "$(field "$d" b fast speedup_significant)" = 0
check "8. the table marks it ~ with the range" grep -q "| fast | ok | 1 | 1.90 (1.70-2.20) | 1.05 (0.818-1.41) ~ |" "$md"
check "8. the answer's noise line" grep -q "^- Noise: every cell ran 3 times; .* 1 of 2 speedups against base have a range that includes 1" "$md"
check "9. busy cell flagged" test "$(field "$d" c fast machine_busy)" = 1
check "9. busy: in the caveats, not in the summary's speedups" grep -q "3 cell runs on a busy machine" "$md"
check "9. busy: fastest counts leave it out (a: fastest, b: a tie inside the spread, c: busy)" grep -q "^| fast | 3 | 3 | 1 (1) | 1 / 0 | " "$md"
check "9. the cell ids of busy runs named" grep -q "c4 (c/fast, 5.00 s of others' CPU)" "$md"

# ---- work precision without reference runs: no trajectory panel, said once
d="$tmp/wp"
mkdir -p "$d/cells"
echo '{"name": "wp", "baseline": "A", "named_axes": []}' >"$d/matrix.json"
echo "id,scene,solver,eps,scale,threads,frames_asked,first_timed_frame,error_ref,set,solver_opts,status,exit,frames,steps,outer_iters,linear_iters,inner_iters,wall_s,timed_frames,timed_wall_s,s_per_frame,max_frame_s,max_residual,converged_fraction,worst_solve_status,particles,peak_rss_mb,startup_s,elapsed_s" >"$d/cells.csv"
for s in A B; do for e in 0.001 1e-05; do
  id="$s$e"
  echo "$id,toy,$s,$e,1,2,1,0,auto,,,ok,0,1,1,1,1,0,1,1,1,1,1,1e-8,1.0,converged,100,10,0.1,1" >>"$d/cells.csv"
  mkdir -p "$d/cells/$id"
  printf 'frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,reason\n0,1,1,1,1,1e-8,converged,""\n' >"$d/cells/$id/frames.csv"
  printf 'frame,step,wall_s,err_h,reason\n0,0,1,%s,""\n' "$e" >"$d/cells/$id/steps.csv"
done; done
"$bin" matrix report "$d" >"$tmp/out" 2>"$tmp/err"
rc=$?
check "wp report exit 0 ($(head -c 300 "$tmp/err"))" test $rc -eq 0
check "11. no trajectory panel, and why" grep -q "No trajectory panel in the figures: the matrix has no reference run" "$d/report.md"
check "11. one-panel work-precision figure (one column wide)" python3 - "$d"/figures/wp_00_*.png <<'PY'
import struct, sys
data = open(sys.argv[1], "rb").read()
w, h = struct.unpack(">II", data[16:24])
assert w == 700, (w, h)
PY
check "11. every PNG has its SVG" bash -c "for p in '$d'/figures/*.png '$tmp'/old/figures/*.png '$tmp'/new/figures/*.png; do test -s \"\${p%.png}.svg\" || exit 1; done"
finish
