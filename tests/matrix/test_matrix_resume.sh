#!/usr/bin/env bash
# A matrix reference with sample_frames is resumable (experiments/matrix/
# matrix_resume.h): the runner is killed (SIGKILL) while the reference
# simulates its animation, after it passed a sampled frame; the next
# `matrix run` goes on from its newest checkpoint (attempt 2, printed), and
# then the reference's steps.csv and frames.csv, and every row of cells.csv,
# equal an uninterrupted run's in everything but times; the reference's
# cost in cells.csv is the sum of its attempts (attempts.csv), its folder
# keeps the sampled checkpoints and loses the resume one. A damaged newest
# checkpoint is passed over for the one before it. A reference stopped
# before any progress record starts over. The kills follow events (a
# checkpoint file, a progress record), not times, so a loaded machine only
# makes the test slower.
. "$(dirname "$0")/../common/shell_harness.sh"
cat >"$tmp/m.json" <<'EOF'
{"name": "resume",
 "defaults": {"threads": 2, "scale": 4},
 "axes": {"scene": ["sauce"], "solver": ["pn-pcg", "hot"]},
 "scenes": {"sauce": {"reference": {"solver": "hot", "eps": 1e-7, "sample_frames": "3,40,80"}}}}
EOF
M=(matrix run "$tmp/m.json" --checkpoint-every-s 1e-6)
"$bin" "${M[@]}" --out "$tmp/full" >"$tmp/full.txt" 2>&1
check "uninterrupted run: exit 0" test $? -eq 0
ref=$(grep "(reference run)" "$tmp/full.txt" | sed 's/^\[[0-9]*\/[0-9]*\] //' | cut -d' ' -f1)
check "the reference's resume checkpoint is gone when it ended" \
  test -f "$tmp/full/cells/$ref/checkpoints/frame_0080.ckpt" -a ! -e "$tmp/full/cells/$ref/checkpoints/resume.ckpt" \
  -a ! -e "$tmp/full/cells/$ref/progress.txt" -a ! -e "$tmp/full/cells/$ref/attempts"

# OUT: start the matrix, kill it once the reference wrote the rows of
# frame 42 (past the sampled frame 40, so a resume from frame 40 must drop
# rows of the attempt) and recorded its progress a second in; "ended" when
# it finished first
interrupt() {
  "$bin" "${M[@]}" --out "$1" >"$1.log" 2>&1 &
  local runner=$! cell="$1/cells/$ref" i
  for i in $(seq 6000); do
    if awk -F, '$3 == 42 {ok = 1} END {exit !ok}' "$cell/frames.csv" 2>/dev/null &&
      awk '$1 == "elapsed_s" && $2 >= 1 {ok = 1} END {exit !ok}' "$cell/progress.txt" 2>/dev/null; then break; fi
    kill -0 "$runner" 2>/dev/null || break
    sleep 0.05
  done
  kill -KILL "$runner" 2>/dev/null
  { wait "$runner"; } 2>/dev/null
  sleep 0.2
  if grep -q "^$ref," "$1/cells.csv" 2>/dev/null; then echo ended; else echo stopped; fi
}

same() { # OUT: the reference's rows and cells.csv equal the uninterrupted run's but for times
  python3 - "$tmp/full" "$1" "$ref" <<'PY'
import csv, sys
full, part, ref = sys.argv[1:]
for name in ("steps.csv", "frames.csv"):
    a = list(csv.DictReader(open(f"{full}/cells/{ref}/{name}")))
    b = list(csv.DictReader(open(f"{part}/cells/{ref}/{name}")))
    keys = [k for k in a[0] if not k.endswith("_s") and k != "threads"]
    assert len(a) == len(b) > 0, (name, len(a), len(b))
    for x, y in zip(a, b):
        d = [k for k in keys if x[k] != y[k]]
        assert not d, (name, x["frame"], d[:3])
times = {"wall_s", "timed_wall_s", "s_per_frame", "max_frame_s", "peak_rss_mb", "startup_s", "elapsed_s", "cpu_s",
         "others_cpu_s", "load_start", "machine_busy"}
ra = {r["id"]: r for r in csv.DictReader(open(f"{full}/cells.csv"))}
rb = {r["id"]: r for r in csv.DictReader(open(f"{part}/cells.csv"))}
assert sorted(ra) == sorted(rb), (sorted(ra), sorted(rb))
for i, r in ra.items():
    d = [k for k in r if k not in times and r[k] != rb[i][k]]
    assert not d, (i, d)
print("ok")
PY
}

resumed() { # OUT NAME FROM: the next matrix run goes on from FROM (attempt 2) and ends as the uninterrupted run
  "$bin" "${M[@]}" --out "$1" >"$1.resumed" 2>&1
  check "run $2 resumed: exit 0" test $? -eq 0
  check "run $2 resumed: it says it goes on from $3" \
    grep -q "^\[resuming\] .*/cells/$ref from .*$3 (attempt 2)" "$1.resumed"
  local out
  out=$(same "$1" 2>&1 | tail -1)
  check "run $2 resumed: the reference's rows and cells.csv equal the uninterrupted run's ($out)" test "$out" = ok
}

state=$(interrupt "$tmp/a")
check "run a: the runner was killed while the reference ran ($state)" test "$state" = stopped
check "run a: no cell process outlives the runner" bash -c "! pgrep -f '^mpmbench run .*$tmp/a/cells' >/dev/null"
check "run a: a resume checkpoint and a progress record" \
  test -f "$tmp/a/cells/$ref/checkpoints/resume.ckpt" -a -f "$tmp/a/cells/$ref/progress.txt"
resumed "$tmp/a" a "/cells/$ref/attempts/1/resume.ckpt"
check "run a resumed: the sampled checkpoints stay, the resume ones and the record go" bash -c "
  cd '$tmp/a/cells/$ref' && test -f checkpoints/frame_0003.ckpt -a -f checkpoints/frame_0040.ckpt \
    -a -f checkpoints/frame_0080.ckpt -a ! -e checkpoints/resume.ckpt -a ! -e attempts/1/resume.ckpt \
    -a ! -e progress.txt -a -f attempts/1/frames.csv -a -f attempts/1/cmd.txt"
out=$(python3 - "$tmp/a" "$ref" <<'PY' 2>&1 | tail -1
import csv, sys
root, ref = sys.argv[1:]
att = list(csv.DictReader(open(f"{root}/cells/{ref}/attempts.csv")))
row = next(r for r in csv.DictReader(open(f"{root}/cells.csv")) if r["id"] == ref)
assert [a["attempt"] for a in att] == ["1", "2"] and att[0]["first_frame"] == "0", att
assert int(att[1]["first_frame"]) >= 40, att[1]
assert float(att[0]["elapsed_s"]) >= 1.0, att[0]  # killed after a record a second in
for k in ("elapsed_s", "cpu_s"):
    total = sum(float(a[k]) for a in att)
    assert abs(float(row[k]) - total) <= 0.01 + 1e-3 * total, (k, row[k], total)
print("ok")
PY
)
check "run a resumed: its cost is the sum of its attempts ($out)" test "$out" = ok
"$bin" "${M[@]}" --out "$tmp/a" >"$tmp/a3.txt" 2>&1
check "run a: a third matrix run has nothing to do" grep -q "0 to run" "$tmp/a3.txt"

# a damaged newest checkpoint (here the resume one) is passed over
state=$(interrupt "$tmp/b")
check "run b: the runner was killed while the reference ran ($state)" test "$state" = stopped
python3 -c "
b = bytearray(open('$tmp/b/cells/$ref/checkpoints/resume.ckpt', 'rb').read()); b[len(b) // 2] ^= 1
open('$tmp/b/cells/$ref/checkpoints/resume.ckpt', 'wb').write(b)"
resumed "$tmp/b" b "/cells/$ref/checkpoints/frame_00[48]0.ckpt" # the sampled one before it

# an attempt without its progress record (stopped before the first, or run by an
# older runner) is not one to go on from: the reference starts over
state=$(interrupt "$tmp/c")
check "run c: the runner was killed while the reference ran ($state)" test "$state" = stopped
rm -f "$tmp/c/cells/$ref/progress.txt"
"$bin" "${M[@]}" --out "$tmp/c" >"$tmp/c2.txt" 2>&1
rc=$?
check "run c ($state): exit 0, started over" bash -c "test $rc -eq 0 && ! grep -q resuming '$tmp/c2.txt' && test ! -e '$tmp/c/cells/$ref/attempts'"
out=$(same "$tmp/c" 2>&1 | tail -1)
check "run c: the rows equal the uninterrupted run's ($out)" test "$out" = ok
finish
