#!/usr/bin/env bash
# steps.csv gets each step's row when the step ends, not when its frame
# ends: a frame of a paper-scale scene takes minutes, and whoever watches
# the file, or stops the run inside a frame, must see the finished steps.
# The run is paused (SIGSTOP) once two step rows are on disk, inside frame 0
# of about 200 steps: frames.csv then has no row yet, and steps.csv ends with
# a whole row. The checks follow files, not times: the poll (every 10 ms)
# only has to see two rows before the run's ~200 steps of frame 0 end (about
# 2.5 s alone, longer on a loaded machine, which slows the run as well). A
# run that wrote its step rows only at a frame's end would show them
# together with frame 0's row.
. "$(dirname "$0")/../common/shell_harness.sh"
data_rows() { # rows under the header (a file whose header is not on disk yet has none)
  local n=0
  [ -f "$1" ] && n=$(($(wc -l <"$1") - 1))
  echo $((n > 0 ? n : 0))
}
"$bin" run --scene drop --frames 1 --set max_dt=0.0002 --solver pn-pcg --threads 1 --quiet --out "$tmp/run" \
  >/dev/null 2>&1 &
pid=$!
while kill -0 $pid 2>/dev/null && [ "$(data_rows "$tmp/run/steps.csv")" -lt 2 ]; do sleep 0.01; done
kill -STOP $pid 2>/dev/null
steps=$(data_rows "$tmp/run/steps.csv")
frames=$(data_rows "$tmp/run/frames.csv")
whole=$(python3 - "$tmp/run/steps.csv" <<'PY'
import csv, sys
text = open(sys.argv[1]).read()
rows = list(csv.reader(text.splitlines()))
print("yes" if text.endswith("\n") and all(len(r) == len(rows[0]) for r in rows) else "no")
PY
)
kill -KILL $pid 2>/dev/null
wait $pid 2>/dev/null
check "two step rows on disk inside frame 0 (steps.csv $steps rows, frames.csv $frames)" test "$steps" -ge 2 -a "$frames" -eq 0
check "steps.csv ends with a whole row ($whole)" test "$whole" = yes
finish
