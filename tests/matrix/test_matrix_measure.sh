#!/usr/bin/env bash
# What cells.csv says of a cell (issue 19): a run stopped by its own
# max_run_seconds is status "time-limit" (not "ok") and the frame it cut short
# is no frame (frames.csv complete = 0; s/frame over the finished frames);
# frames_asked and threads are the counts the run used when the matrix left
# them to the scene / OpenMP (not 0); a description longer than 1,024
# characters reaches matrix.json whole; "repeat": 2 runs every cell twice
# (a column "repeat", the first run keeping the id of a matrix without
# repeat); and a cell run beside processes that keep the cores busy is
# flagged machine_busy = 1 with the CPU seconds they took.
. "$(dirname "$0")/../common/shell_harness.sh"

col() { # csv column-name id
  python3 - "$@" <<'PY'
import csv, sys
for r in csv.DictReader(open(sys.argv[1])):
    if r["id"] == sys.argv[3]:
        print(r[sys.argv[2]])
PY
}
first_id() { # csv python-condition-on-r
  python3 -c "import csv,sys; print([r['id'] for r in csv.DictReader(open(sys.argv[1])) if $2][0])" "$1"
}

desc=$(python3 -c 'print(" ".join(f"word{i:04d}" for i in range(300)))') # 2,699 characters
cat >"$tmp/m.json" <<JSON
{"name": "measure", "description": "$desc",
 "defaults": {"solver": "pn-pcg"},
 "axes": {"scene": ["stretched-box", "drop"]},
 "scenes": {"stretched-box": {"scale": 5, "frames": 2, "first_timed_frame": 1}, "drop": {"scale": 1.5}},
 "exclude": [{"scene": "drop"}]}
JSON
"$bin" matrix run "$tmp/m.json" --dry-run --out "$tmp/once" >"$tmp/dry1.txt"
id_once=$(awk '/stretched-box\/pn-pcg/ {print $1}' "$tmp/dry1.txt")
# the same with repeat 2, and the drop cell stopped by its max_run_seconds
python3 - "$tmp/m.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["repeat"] = 2
del m["exclude"]
m["scenes"]["drop"]["max_run_seconds"] = 1e-6  # any step exhausts it, on any machine
json.dump(m, open(sys.argv[1], "w"))
PY
"$bin" matrix run "$tmp/m.json" --out "$tmp/res" >"$tmp/run.txt" 2>"$tmp/run.err"
rc=$?  # before the description's $(...), which resets $?
check "matrix run exit 0 ($(head -c 300 "$tmp/run.err"))" test $rc -eq 0
cells="$tmp/res/cells.csv"
ids=$(python3 -c 'import csv,sys; print(" ".join(r["id"] for r in csv.DictReader(open(sys.argv[1]))))' "$cells")
check "repeat 2: four rows ($ids)" test "$(echo $ids | wc -w)" -eq 4
check "repeat column" test "$(head -1 "$cells" | tr ',' '\n' | grep -cx repeat)" -eq 1
check "the first run keeps the id of the matrix without repeat" test "$(col "$cells" repeat "$id_once")" = 1
rep2=$(first_id "$cells" 'r["scene"] == "stretched-box" and r["repeat"] == "2"')
check "repetition 2 has an id of its own" test -n "$rep2" -a "$rep2" != "$id_once"
check "repetitions run after all first runs" test "$(grep '^\[' "$tmp/run.txt" | head -2 | grep -c 'repeat=2'),$(grep '^\[' "$tmp/run.txt" | tail -2 | grep -c 'repeat=2')" = "0,2"

drop=$(first_id "$cells" 'r["scene"] == "drop" and r["repeat"] == "1"')
check "a run stopped at its max_run_seconds: status time-limit" test "$(col "$cells" status "$drop")" = time-limit
frames_csv="$tmp/res/cells/$drop/frames.csv"
complete=$(python3 -c 'import csv,sys; print(sum(r["complete"] == "1" for r in csv.DictReader(open(sys.argv[1]))))' "$frames_csv")
rows=$(($(wc -l <"$frames_csv") - 1))
check "frames counts the finished frames only ($complete of $rows rows)" test "$(col "$cells" frames "$drop")" = "$complete"
check "the cut frame's time is in wall_s, not in s_per_frame" python3 - "$cells" "$drop" "$frames_csv" <<'PY'
import csv, sys
row = [r for r in csv.DictReader(open(sys.argv[1])) if r["id"] == sys.argv[2]][0]
fr = list(csv.DictReader(open(sys.argv[3])))
done = [float(f["wall_s"]) for f in fr if f["complete"] == "1"]
assert abs(float(row["s_per_frame"]) - sum(done) / len(done)) < 2e-6, (row["s_per_frame"], done)
assert abs(float(row["wall_s"]) - sum(float(f["wall_s"]) for f in fr)) < 1e-5
PY
scene_frames=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["frames"])' "$tmp/res/cells/$drop/run.json")
check "frames_asked: the scene's count when the matrix gives none ($scene_frames)" test "$(col "$cells" frames_asked "$drop")" = "$scene_frames" -a "$scene_frames" -gt 0
check "threads: OpenMP's count when the matrix gives none" test "$(col "$cells" threads "$drop")" = "${OMP_NUM_THREADS:-2}"
check "description kept whole (2,699 characters)" python3 -c "
import json, sys; d = json.load(open('$tmp/res/matrix.json'))['description']; sys.exit(len(d) != 2699 or not d.endswith('word0299'))"
"$bin" matrix run "$tmp/m.json" --out "$tmp/res" --check >"$tmp/check.txt" 2>&1
check "--check: a run stopped at its own limit passes (it said why)" python3 - "$tmp/res/check.csv" "$drop" <<'PY'
import csv, sys
r = [x for x in csv.DictReader(open(sys.argv[1])) if x["id"] == sys.argv[2]][0]
assert r["pass"] == "1", r
PY
for id in $ids; do
  check "interference columns of $id" python3 - "$cells" "$id" <<'PY'
import csv, sys
r = [x for x in csv.DictReader(open(sys.argv[1])) if x["id"] == sys.argv[2]][0]
assert float(r["cpu_s"]) > 0 and float(r["others_cpu_s"]) >= 0 and float(r["load_start"]) >= 0, r
assert r["machine_busy"] in ("0", "1"), r
PY
done

# two processes spinning beside a 2-thread cell: busy
cat >"$tmp/busy.json" <<'JSON'
{"name": "busy", "defaults": {"solver": "pn-pcg", "threads": 2, "scene": "stretched-box", "scale": 4, "frames": 3}}
JSON
spin() { local end=$((SECONDS + 60)); while [ $SECONDS -lt $end ]; do :; done; }
spin &
s1=$!
spin &
s2=$!
"$bin" matrix run "$tmp/busy.json" --out "$tmp/busy" >"$tmp/busy.txt" 2>&1
kill "$s1" "$s2" 2>/dev/null
wait "$s1" "$s2" 2>/dev/null
bid=$(first_id "$tmp/busy/cells.csv" 'True')
check "beside two spinning processes: machine_busy 1 ($(tail -2 "$tmp/busy.txt"))" test "$(col "$tmp/busy/cells.csv" machine_busy "$bid")" = 1
check "others_cpu_s: the spinners' share" python3 - "$tmp/busy/cells.csv" "$bid" <<'PY'
import csv, sys
r = [x for x in csv.DictReader(open(sys.argv[1])) if x["id"] == sys.argv[2]][0]
assert float(r["others_cpu_s"]) > 0.3 * float(r["elapsed_s"]), r
PY
check "the runner says so" grep -q "machine busy" "$tmp/busy.txt"
echo '{"name": "bad", "defaults": {"solver": "pn-pcg", "scene": "drop"}, "repeat": 0}' >"$tmp/bad.json"
expect_input_error "bad.json: repeat: expected an integer 1..100, got 0" matrix run "$tmp/bad.json" --dry-run
finish
