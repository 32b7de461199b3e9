#!/usr/bin/env bash
# The conventions every command follows (issue 19): --help and -h print the
# command's usage on stdout and exit 0, and `run --help` names every flag of
# the run settings table; --version names the version and the git commit;
# --flag=value is --flag value (the same CSV numbers); an unknown flag or a
# bad value is one line on stderr and exit 2; exit 3 when `matrix run
# --check` finds a failed cell; the top-level usage states the exit
# statuses. tests/unit/test_run_settings.c checks the same per option.
. "$(dirname "$0")/../common/shell_harness.sh"

# every command of the top-level usage
"$bin" --help >"$tmp/usage.txt"
check "--help: exit 0" test $? -eq 0
"$bin" -h >"$tmp/usage-h.txt"
check "-h: the same usage" cmp -s "$tmp/usage.txt" "$tmp/usage-h.txt"
"$bin" >/dev/null 2>"$tmp/none.txt"
check "no command: exit 2, the usage on stderr" test $? -eq 2 -a -s "$tmp/none.txt"
for code in "0  success" "1  internal failure" "2  bad input" "3  matrix run --check"; do
  check "the usage names exit status '$code'" grep -q "^  $code" "$tmp/usage.txt"
done
check "the usage names MPM_PYTHON" grep -q "MPM_PYTHON" "$tmp/usage.txt"
# a command is the lower-case words after "mpmbench" ("matrix run FILE [options]" is "matrix run")
mapfile -t commands < <(awk '/^  mpmbench /{c=$2; for(i=3;i<=NF && $i ~ /^[a-z]+$/;i++) c=c" "$i; print c}' "$tmp/usage.txt")
check "the usage lists the commands (${commands[*]})" test "${#commands[@]}" -ge 6
for c in "${commands[@]}"; do
  # shellcheck disable=SC2086
  "$bin" $c --help >"$tmp/help.txt" 2>"$tmp/help.err"
  check "'$c --help': exit 0, usage on stdout, nothing on stderr" \
    test $? -eq 0 -a ! -s "$tmp/help.err" -a "$(grep -c "^usage: mpmbench $c" "$tmp/help.txt")" -eq 1
  # shellcheck disable=SC2086
  "$bin" $c -h >"$tmp/help-h.txt" 2>&1
  check "'$c -h' = '$c --help'" cmp -s "$tmp/help.txt" "$tmp/help-h.txt"
  # shellcheck disable=SC2086
  "$bin" help $c >"$tmp/help-help.txt" 2>&1
  check "'help $c' = '$c --help'" cmp -s "$tmp/help.txt" "$tmp/help-help.txt"
  # shellcheck disable=SC2086
  expect_input_error "^mpmbench: error: $c: unknown option '--no-such-flag' \\(see: mpmbench $c --help\\)$" $c --no-such-flag
done
"$bin" matrix --help >"$tmp/matrix-help.txt"
check "'matrix --help': exit 0" test $? -eq 0
check "'matrix --help' is the group's usage, not the program's" grep -q "^usage: mpmbench matrix COMMAND" "$tmp/matrix-help.txt"
for sub in run report schema; do
  check "'matrix --help' names 'matrix $sub'" grep -q "^  mpmbench matrix $sub" "$tmp/matrix-help.txt"
done
check "'matrix --help' lists no other command" test "$(grep -c '^  mpmbench ' "$tmp/matrix-help.txt")" -eq 3
"$bin" help matrix >"$tmp/help-matrix.txt"
check "'help matrix' = 'matrix --help'" cmp -s "$tmp/matrix-help.txt" "$tmp/help-matrix.txt"

# run --help names every flag of the run settings table (read from its source)
"$bin" run --help >"$tmp/run-help.txt"
mapfile -t flags < <(grep -o '^    {"--[a-z-]*"' "$src/experiments/cli/run_settings.c" | grep -o -- '--[a-z-]*')
check "the table has its settings (${#flags[@]})" test "${#flags[@]}" -ge 20
for f in "${flags[@]}"; do check "run --help names $f" grep -q -- "^  $f\b" "$tmp/run-help.txt"; done
mapfile -t keys < <(grep -o '^    {"--[a-z-]*", "[a-z_]*"' "$src/experiments/cli/run_settings.c" | grep -o '"[a-z_]*"$' | tr -d '"')
tr -s ' \n' ' ' <"$tmp/run-help.txt" >"$tmp/run-help-line.txt" # help lines are wrapped
for k in "${keys[@]}"; do check "run --help names the matrix key $k" grep -q "matrix key: $k\]" "$tmp/run-help-line.txt"; done

# --version: the version and the commit the binary was built from
"$bin" --version >"$tmp/version.txt"
check "--version: exit 0" test $? -eq 0
check "--version: mpmbench X.Y.Z (git COMMIT) ($(cat "$tmp/version.txt"))" \
  grep -qE '^mpmbench [0-9]+\.[0-9]+\.[0-9]+ \(git ([0-9a-f]{40}|unknown)(, modified)?\)$' "$tmp/version.txt"

# --flag=value and --flag value: the same run
"$bin" run --scene drop --solver pn-pcg --frames 1 --eps 1e-6 --scale 2 --set materials.soft.E=2e5 \
  --solver-opt forcing=gast --max-outer 50 --on-failure continue --quiet --out "$tmp/spaced"
check "--flag value: exit 0" test $? -eq 0
"$bin" run --scene=drop --solver=pn-pcg --frames=1 --eps=1e-6 --scale=2 --set=materials.soft.E=2e5 \
  --solver-opt=forcing=gast --max-outer=50 --on-failure=continue --quiet --out="$tmp/joined"
check "--flag=value: exit 0" test $? -eq 0
counts() { cut -d, -f1-14,22-23 "$1"; } # every column but the timings
check "--flag=value: the same steps.csv" test "$(counts "$tmp/spaced/steps.csv")" = "$(counts "$tmp/joined/steps.csv")"
# settings only: not the times, the machine's load or the output folder's name
settings() {
  python3 - "$1" <<'PY'
import json, sys
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k not in ("start_time", "startup_s", "machine_load")}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v.replace("spaced", "X").replace("joined", "X") if isinstance(v, str) else v
print(json.dumps(strip(json.load(open(sys.argv[1]))), sort_keys=True))
PY
}
check "--flag=value: the same settings in run.json" test "$(settings "$tmp/spaced/run.json")" = "$(settings "$tmp/joined/run.json")"
check "the options reached the run" grep -q '"forcing": "gast"' "$tmp/joined/run.json"

# bad input: one line, exit 2, naming the flag and the value
expect_input_error "^mpmbench: error: --frames 'two': expected an integer >= 1$" run --scene drop --solver pn-pcg --frames two
expect_input_error "^mpmbench: error: --frames '0': expected an integer >= 1$" run --scene drop --solver pn-pcg --frames=0
expect_input_error "^mpmbench: error: --eps '-1': expected a positive number$" run --scene drop --solver pn-pcg --eps=-1
expect_input_error "--on-failure 'retry': expected stop or continue" run --scene drop --solver pn-pcg --on-failure retry
expect_input_error "--quiet takes no value \\(got 'yes'\\)" run --scene drop --solver pn-pcg --quiet=yes
expect_input_error "^mpmbench: error: --out: missing value$" run --scene drop --solver pn-pcg --out
expect_input_error "--set 'E': expected key=value" run --scene drop --solver pn-pcg --set E
expect_input_error "run: --solver is required" run --scene drop
expect_input_error "run: unexpected argument 'drop'" run drop --solver pn-pcg
expect_input_error "--view 'up': expected front, side, top or iso" render --scene drop --view=up
expect_input_error "--jobs '0': expected an integer in \\[1, 1024\\]" matrix run "$src/experiments/matrices/smoke.json" --jobs=0
expect_input_error "list 'solver': expected 'solvers', 'scenes' or 'definitions'" list solver
expect_input_error "bench: expected spmv, hessvec, assemble, tangent, energy, gradient, p2g, g2p or all" bench --scene drop
expect_input_error "--transfer 'pic': expected apic, mls or pic_flip" bench p2g --scene drop --transfer=pic

# exit 3: matrix run --check with a failed cell (killed at its wall-clock limit)
cat >"$tmp/check.json" <<'EOF'
{"name": "exit3", "defaults": {"scene": "drop", "solver": "pn-pcg", "frames": 24, "scale": 2, "threads": 1},
 "cell_timeout_s": 0.2}
EOF
"$bin" matrix run "$tmp/check.json" --out "$tmp/check" >/dev/null 2>"$tmp/run3.err"
check "without --check: exit 0 whatever the cells did" test $? -eq 0
"$bin" matrix run "$tmp/check.json" --out "$tmp/check" --check >"$tmp/check.out" 2>"$tmp/check.err"
check "--check with a failed cell: exit 3" test $? -eq 3
check "--check: one line on stderr" test "$(wc -l <"$tmp/check.err")" -eq 1 -a \
  "$(grep -c 'matrix run --check: 1 of 1 cells failed' "$tmp/check.err")" -eq 1
finish
