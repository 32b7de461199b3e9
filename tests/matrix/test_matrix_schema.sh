#!/usr/bin/env bash
# needs: MPM_WITH_CHOLMOD
# docs/matrix.schema.json (generated: test_matrix_schema_generated.sh)
# describes the matrix-file format the loader accepts: every committed
# experiments/matrices/*.json validates against it,
# and on a set of probe files (every key at every level, unknown keys, wrong
# types) the schema and `mpmbench matrix run --dry-run` agree on valid /
# invalid. Needs python3-jsonschema (installed by scripts/test.sh).
. "$(dirname "$0")/../common/shell_harness.sh"

python3 -c 'import jsonschema' 2>/dev/null ||
  skip "python3-jsonschema is missing (apt-get install python3-jsonschema; scripts/test.sh installs it)"

check "every committed matrix file validates against the schema" python3 "$src/scripts/check_matrices.py"

# probe <name> <valid|invalid> <json>: schema and loader both give the verdict
probe() {
  local name="$1" want="$2" json="$3"
  printf '%s\n' "$json" >"$tmp/$name.json"
  local schema_ok=1 loader_ok=1
  python3 "$src/scripts/check_matrices.py" "$tmp/$name.json" >"$tmp/$name.schema" 2>&1 || schema_ok=0
  "$bin" matrix run "$tmp/$name.json" --dry-run --out "$tmp/out-$name" >"$tmp/$name.loader" 2>&1 || loader_ok=0
  local want_ok=0
  [ "$want" = valid ] && want_ok=1
  checks=$((checks + 1))
  if [ "$schema_ok" != "$want_ok" ] || [ "$loader_ok" != "$want_ok" ]; then
    echo "FAIL: probe $name: wanted $want, schema says $schema_ok, loader says $loader_ok"
    cat "$tmp/$name.schema" "$tmp/$name.loader" | head -5
    fails=$((fails + 1))
  fi
}

ax='"axes": {"scene": ["drop"], "solver": ["hot"]}'
probe minimal valid "{\"name\": \"t\", $ax}"
probe every-default valid '{"name": "t", "description": "d", "defaults": {"scene": "drop", "solver": "hot", "eps": 1e-6,
  "scale": 2, "threads": 1, "frames": 2, "first_timed_frame": 1, "set": {"materials.soft.E": 2e5},
  "solver_opts": {"window": 4}, "history": true, "armijo": false, "particles": false, "asset_dir": ".",
  "error_ref": "pn-pcg:1e-9", "trajectory": false, "max_outer": 50, "max_linear": 500, "max_step_seconds": 10,
  "max_run_seconds": 60, "on_failure": "continue"}}'
probe every-axis valid '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot", "pn-pcg"], "eps": [1e-6, 1e-7],
  "scale": [2], "threads": [1], "error_ref": ["auto"], "sets": {"stiff": [{"materials.soft.E": 1e5}],
  "named": {"soft": {"materials.soft.E": 1e4}}}, "solver_opts": {"ls": [{"linesearch": "armijo"}]}}}'
probe every-scene-key valid "{\"name\": \"t\", $ax, \"scenes\": {\"drop\": {\"scale\": 2, \"frames\": 3,
  \"first_timed_frame\": 1, \"set\": {\"frames\": 3}, \"error_ref\": \"auto\", \"max_outer\": 9, \"max_linear\": 9,
  \"max_step_seconds\": 5, \"max_run_seconds\": 9, \"on_failure\": \"stop\", \"reference\": false}}}"
probe top-level-rest valid "{\"name\": \"t\", $ax, \"include\": [{\"solver\": [\"hot\"]}], \"exclude\": [{\"scene\": \"drop\", \"eps\": 1e-3}],
  \"baseline\": \"hot\", \"cell_timeout_s\": 60, \"report\": {\"mg_levels\": true}, \"repeat\": 3,
  \"reference\": {\"solver\": \"pn-cholmod\", \"eps\": 1e-10, \"solver_opts\": {}}}"
probe scene-reference valid "{\"name\": \"t\", $ax, \"scenes\": {\"drop\": {\"reference\": {\"solver\": \"pn-pcg\"}}}}"

probe no-name invalid "{$ax}"
probe bad-name invalid "{\"name\": \"a b\", $ax}"
probe unknown-top invalid "{\"name\": \"t\", $ax, \"frame\": 3}"
probe unknown-default invalid "{\"name\": \"t\", $ax, \"defaults\": {\"thread\": 2}}"
probe reference-in-defaults invalid "{\"name\": \"t\", $ax, \"defaults\": {\"reference\": {\"solver\": \"hot\"}}}"
probe unknown-axis invalid '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "stiffness": [1]}}'
probe unknown-scene-key invalid "{\"name\": \"t\", $ax, \"scenes\": {\"drop\": {\"threads\": 2}}}"
probe empty-axis invalid '{"name": "t", "axes": {"scene": ["drop"], "solver": []}}'
probe eps-string invalid '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "eps": ["tight"]}}'
probe eps-zero invalid '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "eps": [0]}}'
probe threads-zero invalid "{\"name\": \"t\", $ax, \"defaults\": {\"threads\": 0}}"
probe frames-real invalid "{\"name\": \"t\", $ax, \"scenes\": {\"drop\": {\"frames\": 2.5}}}"
probe first-negative invalid "{\"name\": \"t\", $ax, \"defaults\": {\"first_timed_frame\": -1}}"
probe on-failure-word invalid "{\"name\": \"t\", $ax, \"defaults\": {\"on_failure\": \"retry\"}}"
probe history-number invalid "{\"name\": \"t\", $ax, \"defaults\": {\"history\": 1}}"
probe step-seconds-huge invalid "{\"name\": \"t\", $ax, \"defaults\": {\"max_step_seconds\": 2e9}}"
probe axis-reserved invalid '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"status": [{"frames": 2}]}}}'
probe axis-name-case invalid '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"Stiff": [{"frames": 2}]}}}'
probe axis-empty-set invalid '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"s": [{}]}}}'
probe rule-empty invalid "{\"name\": \"t\", $ax, \"exclude\": [{}]}"
probe rule-empty-list invalid "{\"name\": \"t\", $ax, \"include\": [{\"solver\": []}]}"
probe reference-no-solver invalid "{\"name\": \"t\", $ax, \"reference\": {\"eps\": 1e-9}}"
probe reference-unknown-key invalid "{\"name\": \"t\", $ax, \"reference\": {\"solver\": \"hot\", \"tol\": 1}}"
probe timeout-zero invalid "{\"name\": \"t\", $ax, \"cell_timeout_s\": 0}"
probe repeat-zero invalid "{\"name\": \"t\", $ax, \"repeat\": 0}"
probe repeat-real invalid "{\"name\": \"t\", $ax, \"repeat\": 2.5}"
probe repeat-huge invalid "{\"name\": \"t\", $ax, \"repeat\": 101}"
probe report-unknown invalid "{\"name\": \"t\", $ax, \"report\": {\"figures\": true}}"
# the generated schema knows what the tables know: a table's range, the results tables' columns, the axes
probe threads-huge invalid "{\"name\": \"t\", $ax, \"defaults\": {\"threads\": 2000}}"
probe axis-measure-column invalid '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"steps": [{"frames": 2}]}}}'
probe axis-check-column invalid '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"pass": [{"frames": 2}]}}}'
probe rule-bad-key invalid "{\"name\": \"t\", $ax, \"include\": [{\"Solver\": \"hot\"}]}"
probe rule-named-axis valid '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"stiff": [{"materials.soft.E": 1e5}]}},
  "include": [{"stiff": "1e+05", "eps": 1e-7}]}'
probe reference-eps-zero invalid "{\"name\": \"t\", $ax, \"reference\": {\"solver\": \"hot\", \"eps\": 0}}"
finish
