#!/usr/bin/env bash
# scripts/summarize.py on hand-made runs with known numbers: totals, seconds
# per frame, the time ratio and speedup against the baseline, a frame window
# (--from-frame), an incomplete run, and bad arguments.
. "$(dirname "$0")/shell_harness.sh"

# run DIR SOLVER FRAMES_ASKED "wall outer linear status" per frame...
make_run() {
  local dir="$1" solver="$2" asked="$3"; shift 3
  mkdir -p "$dir"
  printf '{"scene": "toy", "solver": "%s", "scale": 2.0, "eps": 1e-7, "overrides": {}, "frames": %d, "threads": 2, "particles": 100}\n' \
    "$solver" "$asked" >"$dir/run.json"
  echo "scene,solver,frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,threads" >"$dir/frames.csv"
  local f=0
  for row in "$@"; do
    set -- $row
    echo "toy,$solver,$f,2,$2,$3,$1,5e-8,$4,2" >>"$dir/frames.csv"
    f=$((f + 1))
  done
}
make_run "$tmp/runs/base" pn-pcg 4 "1.0 0 0 converged" "4.0 10 100 converged" "4.0 10 100 converged" "4.0 10 100 converged"
make_run "$tmp/runs/fast" hot 4 "1.0 0 0 converged" "1.0 20 10 converged" "1.0 20 10 converged" "1.0 20 10 capped"
make_run "$tmp/runs/cut" lbfgs-h 4 "1.0 0 0 converged" "2.0 5 5 converged"

py() { python3 "$src/scripts/summarize.py" "$@"; }
py --csv "$tmp/all.csv" --no-markdown "$tmp/runs"
check "exit 0" test $? -eq 0
field() { # csv solver column
  python3 -c 'import csv,sys; r=[x for x in csv.DictReader(open(sys.argv[1])) if x["solver"]==sys.argv[2]][0]; print(r[sys.argv[3]])' "$@"
}
check "pn-pcg: 13 s over 4 frames" test "$(field "$tmp/all.csv" pn-pcg s_per_frame)" = "3.250000"
check "hot: 4 s over 4 frames, speedup 3.25" test "$(field "$tmp/all.csv" hot speedup_vs_pn-pcg)" = "3.250000"
check "hot: worst status capped" test "$(field "$tmp/all.csv" hot worst_status)" = "capped"
check "lbfgs-h: incomplete (2 of 4 frames)" test "$(field "$tmp/all.csv" lbfgs-h complete)" = "0"
check "lbfgs-h: ratio from s/frame of the frames done" test "$(field "$tmp/all.csv" lbfgs-h ratio_to_pn-pcg)" = "0.461538"

# timed from frame 1: pn-pcg 12 s / 3 frames, hot 3 s / 3 frames -> speedup 4
py --from-frame toy=1 --csv "$tmp/win.csv" --no-markdown "$tmp/runs"
check "window: pn-pcg 4 s/frame" test "$(field "$tmp/win.csv" pn-pcg s_per_frame)" = "4.000000"
check "window: hot speedup 4" test "$(field "$tmp/win.csv" hot speedup_vs_pn-pcg)" = "4.000000"
check "window: 3 frames timed" test "$(field "$tmp/win.csv" hot frames_timed)" = "3"
check "window: outer iterations inside it" test "$(field "$tmp/win.csv" hot outer_iters)" = "60"
check "window of another scene changes nothing" \
  test "$(py --from-frame other=2 --csv "$tmp/o.csv" --no-markdown "$tmp/runs"; field "$tmp/o.csv" hot s_per_frame)" = "1.000000"
py --from-frame 1 "$tmp/runs" >"$tmp/table.md"
check "markdown shows the window" grep -q "| hot | 1-3 of 4/4 |" "$tmp/table.md"

py --from-frame toy=x "$tmp/runs" >/dev/null 2>"$tmp/err"
check "bad --from-frame: exit 2" test $? -eq 2
check "bad --from-frame: message" grep -q "from-frame toy=x" "$tmp/err"
py "$tmp/nothing-here" >/dev/null 2>&1
check "no runs: exit 2" test $? -eq 2

finish
