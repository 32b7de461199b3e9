#!/usr/bin/env bash
# The Gast15 parts from the command line: the benchmark matrices validate
# and pair every snowball scene's semi-implicit cell with its own stable CFL
# (gast15-fig18.json) and list the tolerance sweep (gast15-table1.json); bad
# values of the new solver options are one-line input errors.
. "$(dirname "$0")/../common/shell_harness.sh"

m="$src/experiments/matrices"
"$bin" matrix run "$m/gast15-table1.json" --dry-run --out "$tmp/t1" >"$tmp/t1.txt" 2>&1
rc=$?  # before the description's $(...), which resets $?
check "gast15-table1 validates ($(tail -1 "$tmp/t1.txt"))" test $rc -eq 0
check "gast15-table1: 26 cells" grep -q ": 26 cells" "$tmp/t1.txt"
check "gast15-table1: bar3 at E_mid 1e9" python3 -c "import json, sys; sys.exit(json.load(open('$m/gast15-table1.json'))['scenes']['bar3']['set']['materials.middle.E'] != 1e9)"
for tau in 1e-1 1e-2 1e-4 1e-5; do
  check "tau $tau swept for gast15 and gast15-hot" test "$(grep -c -e "/gast15:tau=$tau " -e "/gast15-hot:tau=$tau " "$tmp/t1.txt")" -eq 4
done

"$bin" matrix run "$m/gast15-fig18.json" --dry-run --out "$tmp/f18" >"$tmp/f18.txt" 2>&1
rc=$?  # before the description's $(...), which resets $?
check "gast15-fig18 validates ($(tail -1 "$tmp/f18.txt"))" test $rc -eq 0
check "gast15-fig18: 12 cells" grep -q ": 12 cells" "$tmp/f18.txt"
check "semi-implicit on snowball-drop at CFL 2.4" grep -q "snowball-drop/semi-implicit .*solver_setting=cfl 2.4" "$tmp/f18.txt"
check "semi-implicit on snowball-wall at CFL 3.0" grep -q "snowball-wall/semi-implicit .*solver_setting=cfl 3.0" "$tmp/f18.txt"
check "semi-implicit on snowball-collide at CFL 1.8" grep -q "snowball-collide/semi-implicit .*solver_setting=cfl 1.8" "$tmp/f18.txt"
check "every other solver at CFL 0.6" test "$(grep -c "solver_setting=cfl 0.6" "$tmp/f18.txt")" -eq 9

expect_input_error "downhill=euclid: expected mass or l2" run --scene drop --solver gast15:downhill=euclid
expect_input_error "kappa=1.5" run --scene drop --solver gast15:kappa=1.5
expect_input_error "max_step=-1" run --scene drop --solver gast15:max_step=-1
expect_input_error "initial_guess=zero" run --scene drop --solver gast15:initial_guess=zero
expect_input_error "rtol=2" run --scene drop --solver semi-implicit:rtol=2
expect_input_error "linearize=x0" run --scene drop --solver semi-implicit:linearize=x0
expect_input_error "forcing=hot" run --scene drop --solver pn-pcg:forcing=hot
expect_input_error "linesearch=wolf" run --scene drop --solver gast15:linesearch=wolf
finish
