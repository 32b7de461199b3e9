#!/usr/bin/env bash
# needs: MPM_WITH_CHOLMOD
# `mpmbench matrix run`: each cell is a child process whose end becomes its
# status (ok; crashed: killed by SIGSEGV; timeout: over cell_timeout_s, the
# child's process group killed; bad-input: its scene file vanished after
# validation), the matrix goes on, and cells.csv has one row per cell with
# the numbers of the cell's own CSV files. Then resuming: done cells are
# skipped, a row cut short by a crash is dropped, a cell without a row is
# redone from an empty directory (and a killed runner leaves no cell running),
# an axis added to the matrix keeps the ids
# of the cells whose settings it does not change and fills its column in
# the old rows. The cell directory holds the child's quiet output, run.json
# with startup_s and provenance, and cmd.txt, which reproduces the cell.
. "$(dirname "$0")/../common/shell_harness.sh"

col() { # csv column-name [id]: the column of the row with that id (or of every row)
  python3 - "$@" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
for r in rows:
    if len(sys.argv) < 4 or r["id"] == sys.argv[3]:
        print(r[sys.argv[2]])
PY
}

cell_process() { # pattern: the pid of the cell process whose command line matches, once it runs (30 s at most)
  local pid=""
  for _ in $(seq 600); do
    pid=$(pgrep -f "^mpmbench run .*$1" | head -1)
    [ -n "$pid" ] && break
    sleep 0.05
  done
  echo "$pid"
}

cp "$src/experiments/scenes/stretched-box.json" "$tmp/gone.json"
# The 30 s limit leaves the ok cell (about 1 s alone, a few s under ASan) room on a loaded machine
# (at 5 s it timed out in CI's ASan suite while other tests shared the cores); the slow
# cell (drop at scale 1, 600 frames) needs about 2 minutes alone, so it
# reaches the limit on any machine; its kill is checked against 30-45 s
# (the runner needs only to wake, however loaded the machine).
cat >"$tmp/m.json" <<'EOF'
{"name": "statuses",
 "defaults": {"threads": 1, "solver": "pn-pcg"},
 "axes": {"scene": ["stretched-box", "drop", "gone.json"], "eps": [1e-7, 1e-8]},
 "scenes": {"stretched-box": {"scale": 5, "frames": 2, "first_timed_frame": 1}, "drop": {"scale": 1, "frames": 600},
            "gone.json": {"scale": 5, "frames": 1}},
 "exclude": [{"scene": ["stretched-box", "gone.json"], "eps": 1e-8}],
 "cell_timeout_s": 30}
EOF
# In the sanitizer build ASan catches SIGSEGV (even one sent by kill) and
# aborts instead, so the child would end by SIGABRT or SIGSEGV depending on
# whether its handler was installed yet: keep the default disposition there.
[ -n "${ASAN_OPTIONS:-}" ] && export ASAN_OPTIONS="$ASAN_OPTIONS:handle_segv=0"
"$bin" matrix run "$tmp/m.json" --dry-run --out "$tmp/res" >"$tmp/dry.txt"
id_ok=$(awk '/stretched-box\/pn-pcg/ {print $1}' "$tmp/dry.txt")
id_crash=$(awk '/drop\/pn-pcg eps=1e-07/ {print $1}' "$tmp/dry.txt")
id_slow=$(awk '/drop\/pn-pcg eps=1e-08/ {print $1}' "$tmp/dry.txt")
id_gone=$(awk '/gone.json\/pn-pcg/ {print $1}' "$tmp/dry.txt")
check "four cells" test -n "$id_ok" -a -n "$id_crash" -a -n "$id_slow" -a -n "$id_gone"

"$bin" matrix run "$tmp/m.json" --out "$tmp/res" >"$tmp/run.txt" 2>"$tmp/run.err" &
runner=$!
# crash the second cell's child as soon as it runs, and remove the last cell's scene meanwhile
pid=$(cell_process "cells/$id_crash")
check "the second cell runs as a child process" test -n "$pid"
rm -f "$tmp/gone.json"
[ -n "$pid" ] && kill -SEGV "$pid"
wait "$runner"
check "matrix run exit 0 whatever the cells did" test $? -eq 0
csv="$tmp/res/cells.csv"
check "one row per cell" test "$(($(wc -l <"$csv") - 1))" -eq 4
check "ok cell" test "$(col "$csv" status "$id_ok")" = ok
check "crashed cell: status" test "$(col "$csv" status "$id_crash")" = crashed
check "crashed cell: exit -11 (SIGSEGV)" test "$(col "$csv" exit "$id_crash")" = -11
check "timeout cell" test "$(col "$csv" status "$id_slow")" = timeout
check "timeout cell: killed near its limit" python3 -c "import sys; t=float(sys.argv[1]); sys.exit(not 30 <= t < 45)" \
  "$(col "$csv" elapsed_s "$id_slow")"
check "timeout cell: frames done before it are counted" test "$(col "$csv" frames "$id_slow")" -ge 1
check "bad-input cell: status and exit 2" test "$(col "$csv" status "$id_gone"),$(col "$csv" exit "$id_gone")" = bad-input,2
check "bad-input cell: the child's message in its stderr.txt" grep -q "gone.json: scene file not found" "$tmp/res/cells/$id_gone/stderr.txt"
check "no cell process left" bash -c "! pgrep -f '^mpmbench run .*$tmp/res/cells' >/dev/null"
check "runner prints one line per cell" test "$(grep -c '^\[[1-4]/4\] ' "$tmp/run.txt")" -eq 4
check "no progress line into a pipe" test ! -s "$tmp/run.err"

# the ok cell's row holds the numbers of its own CSV files
d="$tmp/res/cells/$id_ok"
check "cell files" test -s "$d/steps.csv" -a -s "$d/frames.csv" -a -s "$d/run.json" -a -s "$d/cmd.txt"
check "the child is quiet" test ! -s "$d/stdout.txt" -a ! -s "$d/stderr.txt"
python3 - "$csv" "$id_ok" "$d" >"$tmp/sums.txt" 2>&1 <<'PY'
import csv, json, sys
row = [r for r in csv.DictReader(open(sys.argv[1])) if r["id"] == sys.argv[2]][0]
steps = list(csv.DictReader(open(sys.argv[3] + "/steps.csv")))
frames = list(csv.DictReader(open(sys.argv[3] + "/frames.csv")))
run = json.load(open(sys.argv[3] + "/run.json"))
assert int(row["steps"]) == len(steps) > 0, (row["steps"], len(steps))
assert int(row["outer_iters"]) == sum(int(s["outer_iters"]) for s in steps) > 0
assert int(row["linear_iters"]) == sum(int(s["linear_iters"]) for s in steps) > 0
assert float(row["max_residual"]) == max(float(s["residual"]) for s in steps)
assert abs(float(row["wall_s"]) - sum(float(f["wall_s"]) for f in frames)) < 1e-5
timed = [float(f["wall_s"]) for f in frames if int(f["frame"]) >= 1]  # first_timed_frame 1
assert int(row["frames"]) == 2 and int(row["timed_frames"]) == len(timed) == 1, row
assert abs(float(row["timed_wall_s"]) - sum(timed)) < 1e-5 and abs(float(row["max_frame_s"]) - max(timed)) < 1e-5
assert abs(float(row["s_per_frame"]) - sum(timed) / len(timed)) < 1e-5
assert float(row["converged_fraction"]) == 1.0 and row["worst_solve_status"] == "converged"
assert float(row["startup_s"]) == round(run["startup_s"], 6) >= 0
assert float(row["peak_rss_mb"]) > 1 and float(row["elapsed_s"]) > 0
p = run["provenance"]
assert len(p["build"]["git_commit"]) >= 7 and p["libraries"]["hypre"] and p["libraries"]["cholmod"], p
assert p["environment"]["OMP_WAIT_POLICY"] == "passive" and p["threads"] == 1 and p["cores_online"] >= 1
print("ok")
PY
check "row = totals of the cell's files; run.json provenance ($(tail -1 "$tmp/sums.txt"))" grep -qx ok "$tmp/sums.txt"
check "provenance.json: one invocation" python3 -c "import json,sys; p=json.load(open(sys.argv[1]))['invocations']; sys.exit(not (len(p)==1 and p[0]['cells_to_run']==4 and 'checkout' in p[0]))" "$tmp/res/provenance.json"
check "matrix.json: the matrix as run" python3 -c "import json,sys; m=json.load(open(sys.argv[1])); sys.exit(m['name']!='statuses' or m['matrix']['cell_timeout_s']!=30)" "$tmp/res/matrix.json"
# cmd.txt reproduces the cell
cmd=$(sed "s|^mpmbench |'$bin' |; s|--out [^ ]*$|--out '$tmp/again'|" "$d/cmd.txt")
bash -c "$cmd" >/dev/null 2>&1
check "cmd.txt reruns the cell: same iterations" test "$(cut -d, -f10,11 "$tmp/again/steps.csv")" = "$(cut -d, -f10,11 "$d/steps.csv")"

# a runner killed while a cell runs takes the cell's process with it
cat >"$tmp/long.json" <<'EOF2'
{"name": "long", "defaults": {"threads": 1, "solver": "pn-pcg", "scene": "drop", "scale": 1.5, "frames": 60}}
EOF2
"$bin" matrix run "$tmp/long.json" --out "$tmp/long" >/dev/null 2>&1 &
runner=$!
child=$(cell_process "$tmp/long/cells")
check "long cell started" test -n "$child"
kill -KILL "$runner"
{ wait "$runner"; } 2>/dev/null
sleep 0.5
check "killed runner: its cell's process is gone" bash -c "! kill -0 $child 2>/dev/null || grep -q '^State:.*Z' /proc/$child/status"

# a matrix naming a scene file that does not exist is refused, done or not
expect_input_error 'm\.json: axes\.scene\[2\]: scene file "gone\.json" not found' matrix run "$tmp/m.json" --out "$tmp/res"
cp "$src/experiments/scenes/stretched-box.json" "$tmp/gone.json"
# resume: nothing to do; a row cut short is dropped; a cell without a row is redone from scratch
"$bin" matrix run "$tmp/m.json" --out "$tmp/res" >"$tmp/again.txt"
check "rerun: 4 done already, 0 to run" grep -q "4 cells, 4 done already, 0 to run" "$tmp/again.txt"
check "rerun: the bad-input cell is not rerun" test "$(($(wc -l <"$csv") - 1))" -eq 4 -a "$(col "$csv" status "$id_gone")" = bad-input
grep -v "^$id_ok," "$csv" >"$tmp/cut.csv"
printf '%s' "$id_ok,stretched-box,pn-pcg,1e-07" >>"$tmp/cut.csv"
cp "$tmp/cut.csv" "$csv"
echo junk >"$d/junk.txt"
"$bin" matrix run "$tmp/m.json" --out "$tmp/res" >"$tmp/resume.txt"
check "resume: the cell whose row was cut reruns" grep -q "3 done already, 1 to run" "$tmp/resume.txt"
check "resume: one whole row per cell again" test "$(col "$csv" status | sort | tr '\n' ' ')" = "bad-input crashed ok timeout "
check "resume: the file ends with a newline" test "$(tail -c1 "$csv" | od -An -c | tr -d ' ')" = '\n'
check "resume: the cell directory was redone" test ! -e "$d/junk.txt" -a -s "$d/frames.csv"

# an added axis: cells whose settings do not change keep their ids and rows
cat >"$tmp/a1.json" <<'EOF'
{"name": "axes", "defaults": {"threads": 1, "scene": "stretched-box", "scale": 5, "frames": 1,
                              "set": {"materials.soft.E": 1e5}},
 "axes": {"solver": ["hot", "pn-pcg"]}}
EOF
"$bin" matrix run "$tmp/a1.json" --out "$tmp/ax" >/dev/null
before=$(col "$tmp/ax/cells.csv" id | sort | tr '\n' ' ')
outer_before=$(col "$tmp/ax/cells.csv" outer_iters | tr '\n' ' ')
sed 's|"axes": {|"axes": {"sets": {"stiff": [{"materials.soft.E": 1e5}, {"materials.soft.E": 2e5}]}, |' "$tmp/a1.json" >"$tmp/a2.json"
"$bin" matrix run "$tmp/a2.json" --out "$tmp/ax" >"$tmp/ax.txt"
check "added axis: 2 done already, 2 to run" grep -q "4 cells, 2 done already, 2 to run" "$tmp/ax.txt"
check "added axis: its column in the header" grep -q "^id,scene,solver,eps,scale,threads,frames_asked,first_timed_frame,stiff,set," "$tmp/ax/cells.csv"
check "added axis: old rows kept, labelled" test "$(col "$tmp/ax/cells.csv" stiff | sort | tr '\n' ' ')" = "1e+05 1e+05 2e+05 2e+05 "
check "added axis: old ids kept" bash -c "for i in $before; do grep -q \"^\$i,\" '$tmp/ax/cells.csv' || exit 1; done"
check "added axis: old numbers kept" test "$(col "$tmp/ax/cells.csv" outer_iters | sed -n 1,2p | tr '\n' ' ')" = "$outer_before"
finish
