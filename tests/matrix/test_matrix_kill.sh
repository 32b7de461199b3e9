#!/usr/bin/env bash
# Crash safety of `mpmbench matrix run`: the runner is killed with SIGKILL at
# random moments (at least 5 kills that hit a live run: while validating,
# while a cell runs, between cells), resumed every time, and finally run to
# the end. cells.csv must then hold exactly one row per cell, equal to those
# of an uninterrupted run in everything but times (iterations, residuals,
# statuses, steps, particles), and no cell process may outlive a kill.
. "$(dirname "$0")/../common/shell_harness.sh"

cat >"$tmp/m.json" <<'EOF'
{"name": "kill", "defaults": {"scene": "stretched-box", "scale": 5, "frames": 1, "threads": 1},
 "axes": {"solver": ["hot", "pn-pcg", "lbfgs-h"], "eps": [1e-6, 1e-7, 1e-8]}}
EOF
t0=$(date +%s%N)
"$bin" matrix run "$tmp/m.json" --out "$tmp/ref" >/dev/null
check "uninterrupted run exit 0" test $? -eq 0
span_ms=$((($(date +%s%N) - t0) / 1000000)) # kills fall anywhere in a run's length

RANDOM=$$
kills=0
round=1
rows() { echo "$(($(cat "$tmp/res$round/cells.csv" 2>/dev/null | wc -l) - 1))"; }
# each kill falls at a random moment of the first quarter of a run's length, so
# a run is killed several times (while validating, inside a cell, between
# cells) before it completes; a run that completes before 5 kills starts a
# new round in a fresh directory
while [ "$kills" -lt 5 ]; do
  "$bin" matrix run "$tmp/m.json" --out "$tmp/res$round" >>"$tmp/log.txt" 2>&1 &
  runner=$!
  ms=$((50 + (RANDOM * 32768 + RANDOM) % (span_ms / 4 + 1)))
  sleep "$((ms / 1000)).$(printf '%03d' $((ms % 1000)))"
  state=$(awk '{print $3}' "/proc/$runner/stat" 2>/dev/null) # Z: it ended already (not yet reaped)
  if [ -n "$state" ] && [ "$state" != Z ] && kill -KILL "$runner" 2>/dev/null; then
    kills=$((kills + 1))
    echo "kill $kills at $ms ms: round $round, $(rows) rows"
  fi
  { wait "$runner"; } 2>/dev/null
  sleep 0.1
  # no cell process survives its runner (the children get SIGKILL when it dies)
  if pgrep -f "^mpmbench run .*$tmp/res$round/cells" >/dev/null; then
    sleep 1
    check "no orphaned cell after kill $kills" bash -c "! pgrep -f '^mpmbench run .*$tmp/res$round/cells' >/dev/null"
  fi
  if [ "$(rows)" -ge 9 ] && [ "$kills" -lt 5 ]; then round=$((round + 1)); fi
done
check "5 kills hit a live run" test "$kills" -ge 5
for r in $(seq "$round"); do
  "$bin" matrix run "$tmp/m.json" --out "$tmp/res$r" >"$tmp/last.txt" 2>&1
  check "final resume of round $r: exit 0" test $? -eq 0
done

for r in $(seq "$round"); do
python3 - "$tmp/ref/cells.csv" "$tmp/res$r/cells.csv" >"$tmp/cmp.txt" 2>&1 <<'PY'
import csv, sys
times = {"wall_s", "timed_wall_s", "s_per_frame", "max_frame_s", "peak_rss_mb", "startup_s", "elapsed_s",
         "cpu_s", "others_cpu_s", "load_start", "machine_busy"}
ref = list(csv.DictReader(open(sys.argv[1])))
got = list(csv.DictReader(open(sys.argv[2])))
ids = [r["id"] for r in got]
assert len(ids) == len(set(ids)), f"duplicate rows: {sorted(ids)}"
assert sorted(ids) == sorted(r["id"] for r in ref), f"cells differ: {sorted(ids)}"
by_id = {r["id"]: r for r in ref}
for r in got:
    a = {k: v for k, v in r.items() if k not in times}
    b = {k: v for k, v in by_id[r["id"]].items() if k not in times}
    assert a == b, f"row {r['id']} differs:\n{a}\n{b}"
    assert r["status"] == "ok" and int(r["outer_iters"]) > 0, r
print(f"ok: {len(got)} rows")
PY
check "round $r: one row per cell, equal to the uninterrupted run's ($(tail -1 "$tmp/cmp.txt"))" grep -q "^ok" "$tmp/cmp.txt"
check "round $r: no cell directory but the matrix's" test "$(ls "$tmp/res$r/cells" | wc -l)" -eq 9
done
finish
