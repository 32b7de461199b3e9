#!/usr/bin/env bash
# needs: MPM_WITH_CHOLMOD
# Reference runs and the new keys of experiment matrices (issue 10): a
# "reference" spec gives each scene a reference cell of its own, run first;
# its dependents get --dt-from/--trajectory-ref with its directory and start
# only after it finished (with --jobs 3, and across MPI ranks), share it, and
# carry its id in their settings; resume keeps a finished reference and
# reruns only what is missing; a reference that did not end ok skips its
# dependents (no row) and --check then fails them; --only keeps the
# references of the cells it selects; error_ref, trajectory and the limits
# reach the cell's command line; matrices without the new keys keep their
# columns and ids.
. "$(dirname "$0")/../common/shell_harness.sh"

col() { # csv column [key-column value]: values of the column (of the rows where key-column = value)
  python3 - "$@" <<'PY'
import csv, sys
for r in csv.DictReader(open(sys.argv[1])):
    if len(sys.argv) < 4 or r[sys.argv[3]] == sys.argv[4]:
        print(r[sys.argv[2]])
PY
}
after() { # file-a file-b: a was last written after b (nanoseconds)
  python3 -c "import os, sys; sys.exit(not os.stat(sys.argv[1]).st_mtime_ns >= os.stat(sys.argv[2]).st_mtime_ns)" "$1" "$2"
}
cat >"$tmp/m.json" <<'EOF'
{"name": "acc",
 "defaults": {"threads": 1, "error_ref": "pn-pcg:1e-10", "max_outer": 500, "max_step_seconds": 30, "on_failure": "continue"},
 "axes": {"scene": ["bar3", "drop"], "solver": ["pn-pcg", "hot"], "eps": [1e-5, 1e-7]},
 "scenes": {"bar3": {"scale": 6, "frames": 2}, "drop": {"scale": 3, "frames": 1, "reference": false}},
 "reference": {"solver": "pn-cholmod", "eps": 1e-10}}
EOF
"$bin" matrix run "$tmp/m.json" --out "$tmp/r" --dry-run >"$tmp/dry.txt"
check "dry run: 1 reference + 8 cells" grep -q "acc (.*): 9 cells" "$tmp/dry.txt"
check "dry run: the reference first" bash -c "sed -n 2p '$tmp/dry.txt' | grep -q 'bar3/pn-cholmod eps=1e-10 .*(reference run)'"
ref=$(sed -n 2p "$tmp/dry.txt" | cut -d' ' -f1)
check "dry run: bar3 cells name it" test "$(grep -c "reference=$ref" "$tmp/dry.txt")" -eq 4
check "dry run: drop cells have none (reference false)" test "$(grep 'drop/' "$tmp/dry.txt" | grep -c 'reference=')" -eq 0

"$bin" matrix run "$tmp/m.json" --out "$tmp/r" --jobs 3 >"$tmp/run.txt" 2>&1
check "run: exit 0" test $? -eq 0
csv="$tmp/r/cells.csv"
check "cells.csv: error_ref, role and reference columns" \
  bash -c "head -1 '$csv' | grep -q '^id,scene,solver,eps,scale,threads,frames_asked,first_timed_frame,error_ref,role,reference,set,'"
check "one reference row" test "$(col "$csv" role | grep -c reference)" -eq 1 -a "$(col "$csv" id role reference)" = "$ref"
check "every cell ok" test "$(col "$csv" status | sort -u)" = ok
check "bar3 cells point at it" test "$(col "$csv" reference scene bar3 | sort -u | tr '\n' ' ')" = " $ref "
d="$tmp/r/cells"
check "the reference wrote its trajectory and no per-step error" test -s "$d/$ref/trajectory.bin" -a \
  "$(col "$d/$ref/steps.csv" err_h | sort -u)" = ""
for id in $(col "$csv" id scene bar3); do
  [ "$id" = "$ref" ] && continue
  check "$id: --dt-from and --trajectory-ref the reference" grep -q -- "--dt-from $tmp/r/cells/$ref --trajectory-ref $tmp/r/cells/$ref" "$d/$id/cmd.txt"
  check "$id: its dt are the reference's" test "$(col "$d/$id/steps.csv" dt)" = "$(col "$d/$ref/steps.csv" dt)"
  check "$id: trajectory error at every frame" test "$(col "$d/$id/frames.csv" pos_rms | grep -c 'e')" -eq 2
  check "$id: started after the reference ended" after "$d/$id/cmd.txt" "$d/$ref/frames.csv"
done
for id in $(col "$csv" id scene drop); do
  check "$id: no reference flags" bash -c "! grep -q -- '--dt-from' '$d/$id/cmd.txt'"
done
any=$(col "$csv" id solver hot | head -1)
check "the keys reach the command line" grep -q -- "--error-ref pn-pcg:1e-10 --max-outer 500 --max-step-seconds 30 --on-failure continue" "$d/$any/cmd.txt"
check "per-step errors measured" test "$(col "$d/$any/steps.csv" ref_solver | sort -u)" = pn-pcg

# resume: the reference stays, the missing dependents rerun
ref_mtime=$(stat -c %Y.%y "$d/$ref/trajectory.bin")
python3 - "$csv" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
h = rows[0]
keep = [rows[0]] + [r for r in rows[1:] if not (r[h.index("scene")] == "bar3" and r[h.index("role")] == "cell")]
csv.writer(open(sys.argv[1], "w", newline="")).writerows(keep)
PY
"$bin" matrix run "$tmp/m.json" --out "$tmp/r" >"$tmp/resume.txt" 2>&1
check "resume: 4 to run" grep -q "9 cells, 5 done already, 4 to run" "$tmp/resume.txt"
check "resume: the reference not rerun" test "$(stat -c %Y.%y "$d/$ref/trajectory.bin")" = "$ref_mtime"
check "resume: all rows back" test "$(($(wc -l <"$csv") - 1))" -eq 9

# --only a dependent: its reference comes along
"$bin" matrix run "$tmp/m.json" --out "$tmp/only" --only 'bar3/hot' >"$tmp/only.txt" 2>&1
check "--only bar3/hot: the reference and 2 cells" grep -q "3 cells, 0 done already, 3 to run" "$tmp/only.txt"

# a reference that does not end ok: its dependents are skipped, without rows, and fail --check
cat >"$tmp/bad.json" <<'EOF'
{"name": "badref", "defaults": {"threads": 1, "scene": "drop", "scale": 1.5},
 "axes": {"solver": ["pn-pcg", "hot"]}, "reference": {"solver": "pn-pcg", "eps": 1e-12},
 "cell_timeout_s": 1}
EOF
"$bin" matrix run "$tmp/bad.json" --out "$tmp/b" --check >"$tmp/bad.txt" 2>"$tmp/bad.err"
check "failed reference: --check exits 3" test $? -eq 3
check "failed reference: the reference timed out" test "$(col "$tmp/b/cells.csv" status role reference)" = timeout
check "failed reference: dependents skipped, no rows" test "$(grep -c '^\[skipped\]' "$tmp/bad.txt")" -eq 2 -a \
  "$(($(wc -l <"$tmp/b/cells.csv") - 1))" -eq 1
check "failed reference: --check names them not run" test "$(grep -c '^check: FAIL .*not run' "$tmp/bad.txt")" -eq 2
check "failed reference: one error line" grep -q "matrix run --check: 3 of 3 cells failed" "$tmp/bad.err"
"$bin" matrix run "$tmp/bad.json" --out "$tmp/b" >"$tmp/bad2.txt" 2>&1
check "failed reference, resumed: still skipped (the reference's row stays)" test "$(grep -c '^\[skipped\] .*ended timeout in an earlier run' "$tmp/bad2.txt")" -eq 2

# matrices without the new keys: no new columns, ids as before (the FNV-1a of the canonical text the runner always wrote)
cat >"$tmp/plain.json" <<'EOF'
{"name": "plain", "defaults": {"scene": "drop", "scale": 3, "frames": 1, "threads": 1}, "axes": {"solver": ["hot"]}}
EOF
"$bin" matrix run "$tmp/plain.json" --out "$tmp/p" --dry-run >"$tmp/plain.txt"
check "plain matrix: the id it always had" grep -q "^bd1ff00e495e  todo  drop/hot" "$tmp/plain.txt"

if command -v mpirun >/dev/null; then
  mpirun_ranks -np 2 "$bin" matrix run "$tmp/m.json" --out "$tmp/mpi" \
    >"$tmp/mpi.txt" 2>"$tmp/mpi.err"
  rc=$?  # before the description's $(...), which resets $?
  check "mpirun -np 2: exit 0 ($(head -c 300 "$tmp/mpi.err"))" test $rc -eq 0
  check "mpirun: all 9 cells ok" test "$(col "$tmp/mpi/cells.csv" status | grep -c ok)" -eq 9
  m="$tmp/mpi/cells"
  for id in $(col "$tmp/mpi/cells.csv" id scene bar3); do
    [ "$id" = "$ref" ] && continue
    check "mpirun $id: started after the reference ended" after "$m/$id/cmd.txt" "$m/$ref/frames.csv"
    check "mpirun $id: the reference's dt" test "$(col "$m/$id/steps.csv" dt)" = "$(col "$m/$ref/steps.csv" dt)"
  done
fi
finish
