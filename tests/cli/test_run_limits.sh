#!/usr/bin/env bash
# needs: MPM_WITH_CHOLMOD
# Robustness of the run loop (issue 12 items 2, 3, 9): a numerical breakdown
# becomes a step row with status failed and its reason, and the run stops
# (exit 0) by the default policy; the work per step and per run is bounded
# by flags (capped, timeout); a stagnated solve reports stalled; an eps below
# double precision's reach and malformed integer solver options are refused
# with one line before any work; solver specs compose any outer method with
# any inverse approximation whose capabilities fit.
. "$(dirname "$0")/../common/shell_harness.sh"

# column of a CSV header field (1-based)
col() { head -1 "$1" | tr ',' '\n' | grep -nx "$2" | cut -d: -f1; }
# field $2 of the last row of CSV $1 (the reason is the last, quoted, column)
last() { local c; c=$(col "$1" "$2"); tail -1 "$1" | cut -d, -f"$c"; }
reason() { tail -1 "$1" | sed 's/.*,"\(.*\)"$/\1/'; }
rows() { echo $(($(wc -l <"$1") - 1)); }
uniform_F() { echo "objects.0.initial_F={\"type\":\"random_diagonal\",\"min\":$1,\"max\":$1}"; }
small=(--scene drop --scale 2.5 --quiet)

# --- breakdowns: failed row with the reason, run stops, exit 0 ---
"$bin" run "${small[@]}" --frames 2 --solver pn-pcg --set "$(uniform_F 1e12)" --out "$tmp/f12" 2>"$tmp/f12.err"
check "F x 1e12: exit 0" test $? -eq 0
check "F x 1e12: one step row, status failed" test "$(rows "$tmp/f12/steps.csv")" -eq 1 -a "$(last "$tmp/f12/steps.csv" status)" = failed
check "F x 1e12: reason is the PCG breakdown ($(reason "$tmp/f12/steps.csv"))" grep -q 'pcg: r^T M^-1 r = -' <(reason "$tmp/f12/steps.csv")
check "F x 1e12: frames.csv row failed with the reason" test "$(last "$tmp/f12/frames.csv" status)" = failed -a "$(reason "$tmp/f12/frames.csv")" = "$(reason "$tmp/f12/steps.csv")"
check "F x 1e12: one line on stderr says the run stopped" test "$(grep -c 'run stopped: frame 0 step 0 failed: pcg' "$tmp/f12.err")" -eq 1

"$bin" run --scene drop --scale 3 --quiet --frames 1 --solver pn-cholmod --set "$(uniform_F 50)" --out "$tmp/f50" 2>/dev/null
check "F = 50 I, pn-cholmod: exit 0" test $? -eq 0
check "F = 50 I, pn-cholmod: failed, not positive definite" grep -q "not positive definite" <(reason "$tmp/f50/steps.csv")
check "F = 50 I: status failed" test "$(last "$tmp/f50/steps.csv" status)" = failed

for s in pn-pcg hot; do
  "$bin" run "${small[@]}" --frames 2 --solver $s --set "$(uniform_F 1e60)" --out "$tmp/nan-$s" 2>/dev/null
  check "F x 1e60 ($s): exit 0" test $? -eq 0
  check "F x 1e60 ($s): failed on a non-finite value" test "$(last "$tmp/nan-$s/steps.csv" status)" = failed
  check "F x 1e60 ($s): reason" grep -q "non-finite" <(reason "$tmp/nan-$s/steps.csv")
  check "F x 1e60 ($s): max_residual is nan in frames.csv" grep -qi "nan" <(last "$tmp/nan-$s/frames.csv" max_residual)
done

# --- bounds on the work ---
"$bin" run --scene stretched-box --scale 5 --quiet --frames 1 --solver hot --max-outer 2 --out "$tmp/cap"
check "--max-outer 2: exit 0" test $? -eq 0
check "--max-outer 2: every step capped at 2 outer iterations" awk -F, -v o="$(col "$tmp/cap/steps.csv" outer_iters)" -v s="$(col "$tmp/cap/steps.csv" status)" 'NR > 1 && ($o != 2 || $s != "capped") {bad = 1} END {exit bad || NR < 2}' "$tmp/cap/steps.csv"
check "--max-outer 2: reason names the cap" grep -q "outer iteration cap 2 reached" <(reason "$tmp/cap/steps.csv")
"$bin" run --scene stretched-box --scale 5 --quiet --frames 1 --solver pn-pcg --max-linear 3 --out "$tmp/lin"
check "--max-linear 3: at most 3 PCG iterations per Newton step" awk -F, -v o="$(col "$tmp/lin/steps.csv" outer_iters)" -v l="$(col "$tmp/lin/steps.csv" linear_iters)" 'NR > 1 && $l > 3 * $o {bad = 1} END {exit bad}' "$tmp/lin/steps.csv"
"$bin" run --scene stretched-box --scale 5 --quiet --frames 1 --solver pn-pcg --out "$tmp/nolin"
check "without --max-linear the same step takes more than 3 PCG iterations per Newton step" awk -F, -v o="$(col "$tmp/nolin/steps.csv" outer_iters)" -v l="$(col "$tmp/nolin/steps.csv" linear_iters)" 'NR > 1 && $l > 3 * $o {more = 1} END {exit !more}' "$tmp/nolin/steps.csv"
"$bin" run --scene stretched-box --scale 5 --quiet --frames 2 --solver pn-pcg --max-step-seconds 1e-9 --out "$tmp/step-t"
check "--max-step-seconds: exit 0, every frame written" test $? -eq 0 -a "$(last "$tmp/step-t/frames.csv" frame)" = 1
check "--max-step-seconds: steps end as timeout" grep -q ',timeout,' "$tmp/step-t/steps.csv"
check "--max-step-seconds: reason names the flag" grep -q -- "--max-step-seconds 1e-09" "$tmp/step-t/steps.csv"
"$bin" run --scene stretched-box --scale 5 --quiet --frames 3 --solver pn-pcg --max-run-seconds 1e-9 --out "$tmp/run-t" 2>"$tmp/run-t.err"
check "--max-run-seconds: exit 0" test $? -eq 0
check "--max-run-seconds: one step row, timeout" test "$(rows "$tmp/run-t/steps.csv")" -eq 1 -a "$(last "$tmp/run-t/steps.csv" status)" = timeout
check "--max-run-seconds: frame row timeout, run stopped" test "$(last "$tmp/run-t/frames.csv" status)" = timeout -a "$(grep -c 'run stopped: time limit --max-run-seconds' "$tmp/run-t.err")" -eq 1
grep -qE '"max_run_seconds": 1(\.0*1?)?e-0?9' "$tmp/run-t/run.json"
check "run.json records the limits" test $? -eq 0

# --- stagnation: an eps at double precision's floor ends as stalled ---
"$bin" run --scene stretched-box --scale 5 --quiet --frames 1 --solver pn-pcg --eps 1e-17 --max-outer 300 --out "$tmp/stall"
check "eps 1e-17: stalled, not capped or looping ($(last "$tmp/stall/steps.csv" status) after $(last "$tmp/stall/steps.csv" outer_iters))" test "$(last "$tmp/stall/steps.csv" status)" = stalled
check "eps 1e-17: within 100 outer iterations" test "$(last "$tmp/stall/steps.csv" outer_iters)" -lt 100

# --- input refused before any work: one line, exit 2, no output folder ---
# a mass that would underflow the solve's sums is refused at load, naming the field
expect_input_error "materials.soft.density 1e-300\) are not in \[1e-200, 1e200\]" run --scene drop --solver pn-pcg --set materials.soft.density=1e-300
expect_input_error "--eps 1e-300: below 9.25e-18" run --scene drop --solver pn-pcg --eps 1e-300
expect_input_error "--eps 9e-18: below" run --scene drop --solver pn-pcg --eps 9e-18
expect_input_error "window=2.5: expected an integer in \[1, 64\]" run --scene drop --solver hot --solver-opt window=2.5 --out "$tmp/never"
check "no output folder for refused input" test ! -e "$tmp/never"
expect_input_error "window=1e10: expected an integer" run --scene drop --solver hot --solver-opt window=1e10
expect_input_error "coarse_max_iters=1.5: expected an integer" run --scene drop --solver hot --solver-opt coarse_max_iters=1.5
expect_input_error "max_iters=0: expected an integer" run --scene drop --solver lbfgs-h --solver-opt max_iters=0
expect_input_error "levels=nan: expected a number" run --scene drop --solver hot --solver-opt levels=nan
# the solver is validated before the scene is even looked up
expect_input_error "window=2.5" run --scene nosuchscene --solver hot --solver-opt window=2.5
expect_input_error "--max-outer '0': expected an integer >= 1" run --scene drop --solver pn-pcg --max-outer 0
expect_input_error "--max-linear 'x': expected an integer" run --scene drop --solver pn-pcg --max-linear x
expect_input_error "--max-step-seconds '-1': expected seconds in \\(0, 1e9\\]" run --scene drop --solver pn-pcg --max-step-seconds -1
expect_input_error "--max-run-seconds 'nan'" run --scene drop --solver pn-pcg --max-run-seconds nan
expect_input_error "--on-failure 'maybe'" run --scene drop --solver pn-pcg --on-failure maybe
expect_input_error "--out '': expected a directory" run --scene drop --solver pn-pcg --out ""
touch "$tmp/afile"
expect_input_error "--out .*afile'?: exists and is not a directory" run --scene drop --solver pn-pcg --out "$tmp/afile"

# --- compositions ---
"$bin" list solvers >"$tmp/list"
check "list solvers: outer methods" grep -q "^  lbfgs " "$tmp/list"
check "list solvers: inverse approximations with capabilities" grep -q "^  sgs .*needs the assembled Hessian" "$tmp/list"
expect_input_error "pn:sgs:matrix_free=1: inverse approximation 'sgs' needs the assembled Hessian.*outer method 'pn'" run --scene drop --solver pn:sgs:matrix_free=1
expect_input_error "unknown inverse approximation 'nosuch' \(registered: block-jacobi" run --scene drop --solver pn:nosuch
expect_input_error "unknown outer method 'newton'" run --scene drop --solver newton:sgs
expect_input_error "hot:window=x.*expected a number|window=x: expected a number" run --scene drop --solver hot:window=x
for spec in lbfgs:sgs pn:mg:embedding=quadratic; do
  "$bin" run --scene stretched-box --scale 5 --quiet --frames 1 --solver "$spec" --out "$tmp/c-${spec//[:=]/_}"
  check "$spec runs and converges" awk -F, -v s="$(col "$tmp/c-${spec//[:=]/_}/steps.csv" status)" 'NR > 1 && $s != "converged" {bad = 1} END {exit bad || NR < 2}' "$tmp/c-${spec//[:=]/_}/steps.csv"
done
# a preset is its composition, step for step (fields by name: a spec with
# options is a quoted CSV field with commas)
iters() {
  python3 -c 'import csv, sys
for r in csv.DictReader(open(sys.argv[1])):
    print(*(r[k] for k in ("outer_iters", "linear_iters", "ls_evals", "residual", "status", "inner_iters")))' "$1"
}
for pair in "hot lbfgs:mg:smoother_precision=single" "pn-pcg-mf pn:block-jacobi:matrix_free=1" \
  "lbfgs-gmg lbfgs:mg:rediscretize=1,smoother_precision=single"; do
  set -- $pair
  "$bin" run --scene stretched-box --scale 5 --quiet --frames 1 --solver "$1" --out "$tmp/p-$1"
  "$bin" run --scene stretched-box --scale 5 --quiet --frames 1 --solver "$2" --out "$tmp/q-$1"
  check "$1 = $2 step for step" test "$(iters "$tmp/p-$1/steps.csv")" = "$(iters "$tmp/q-$1/steps.csv")"
done
# the statistics contract: L-BFGS solves no linear systems of its own; its
# inverse approximation's PCG iterations are inner iterations
check "hot: linear_iters 0, inner_iters > 0" awk -F, -v l="$(col "$tmp/p-hot/steps.csv" linear_iters)" -v i="$(col "$tmp/p-hot/steps.csv" inner_iters)" 'NR > 1 {L += $l; I += $i} END {exit !(L == 0 && I > 0)}' "$tmp/p-hot/steps.csv"
check "mg_levels.csv written through the view op" test "$(head -1 "$tmp/p-hot/mg_levels.csv")" = "level,nodes,blocks,blocks_per_row_avg,blocks_per_row_max"
check "inverse_stats.csv: AMG-free mg statistics" grep -q "^mg,levels," "$tmp/p-hot/inverse_stats.csv"

finish
