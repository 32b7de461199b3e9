#!/usr/bin/env bash
# Matrix files are validated like scenes: every bad file gives exit 2 and one
# line naming the file, the JSON path of the field and the bad value (unknown
# key, unknown scene / solver / option, empty axis, wrong type, bad rule,
# a solver option the solver does not take, a --set path the scene does not
# have), before any cell runs; --dry-run lists the cells; --only selects.
. "$(dirname "$0")/../common/shell_harness.sh"

head='"name": "t", "defaults": {"frames": 1, "scale": 5}'
good="$head"', "axes": {"scene": ["stretched-box"], "solver": ["hot", "pn-pcg"]}'
mk() { printf '%s\n' "$2" >"$tmp/$1.json"; }
bad() { # name, pattern, json
  mk "$1" "$3"
  expect_input_error "$2" matrix run "$tmp/$1.json" --out "$tmp/out-$1"
  check "$1: nothing written" test ! -e "$tmp/out-$1/cells.csv"
}

bad unknown-top '^mpmbench: error: unknown-top\.json: frame: unknown key \(known: name,' "{$good, \"frame\": 3}"
bad unknown-default 'unknown-default\.json: defaults\.thread: unknown key' \
  '{"name": "t", "defaults": {"thread": 2}, "axes": {"scene": ["drop"], "solver": ["hot"]}}'
bad unknown-axis 'unknown-axis\.json: axes\.stiffness: unknown key' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "stiffness": [1]}}'
bad unknown-scene 'unknown-scene\.json: axes\.scene\[1\]: unknown scene "dorp"' \
  '{"name": "t", "axes": {"scene": ["drop", "dorp"], "solver": ["hot"]}}'
bad missing-scene-file 'missing-scene-file\.json: defaults\.scene: scene file "nope/x\.json" not found' \
  '{"name": "t", "defaults": {"scene": "nope/x.json"}, "axes": {"solver": ["hot"]}}'
bad unknown-solver 'unknown-solver\.json: axes\.solver\[0\]: unknown solver .hott.' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hott"]}}'
bad empty-axis 'empty-axis\.json: axes\.solver: empty list' '{"name": "t", "axes": {"scene": ["drop"], "solver": []}}'
bad empty-set-axis 'empty-set-axis\.json: axes\.sets\.stiff: empty list' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"stiff": []}}}'
bad eps-type 'eps-type\.json: axes\.eps\[1\]: expected a positive number, got "tight"' \
  "{$head, \"axes\": {\"scene\": [\"drop\"], \"solver\": [\"hot\"], \"eps\": [1e-7, \"tight\"]}}"
bad threads-zero 'threads-zero\.json: defaults\.threads: expected an integer number of threads in \[1, 1024\], got 0' \
  '{"name": "t", "defaults": {"threads": 0}, "axes": {"scene": ["drop"], "solver": ["hot"]}}'
bad frames-real 'frames-real\.json: scenes\.drop\.frames: expected an integer >= 1, got 2\.5' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"]}, "scenes": {"drop": {"frames": 2.5}}}'
bad axis-not-list 'axis-not-list\.json: axes\.scale: expected a list of values, got 2' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "scale": 2}}'
bad no-name 'no-name\.json: name: missing' '{"axes": {"scene": ["drop"], "solver": ["hot"]}}'
bad no-solver 'no-solver\.json: axes\.solver: missing' '{"name": "t", "axes": {"scene": ["drop"]}}'
bad bad-name 'bad-name\.json: name: expected 1-63 of' '{"name": "a b", "axes": {"scene": ["drop"], "solver": ["hot"]}}'
bad timeout 'timeout\.json: cell_timeout_s: expected a positive number, got -1' "{$good, \"cell_timeout_s\": -1}"
bad baseline 'baseline\.json: baseline: "lbfgs-h" is not a solver of the matrix' "{$good, \"baseline\": \"lbfgs-h\"}"
bad scenes-key 'scenes-key\.json: scenes\.drop: "drop" is not a scene of the matrix' "{$good, \"scenes\": {\"drop\": {\"scale\": 2}}}"
bad scene-key 'scene-key\.json: scenes\.stretched-box\.eps: unknown key' \
  "{$good, \"scenes\": {\"stretched-box\": {\"eps\": 1e-8}}}"
bad rule-axis 'rule-axis\.json: exclude\[0\]: unknown axis "solvers"' "{$good, \"exclude\": [{\"solvers\": \"hot\"}]}"
bad rule-value 'rule-value\.json: include\[0\]\.solver\[1\]: "lbfgs-h" is not a value of the matrix.s solver' \
  "{$good, \"include\": [{\"solver\": [\"hot\", \"lbfgs-h\"]}]}"
bad rule-type 'rule-type\.json: exclude\[0\]\.eps: expected a positive number, got "small"' \
  "{$good, \"exclude\": [{\"eps\": \"small\"}]}"
bad axis-name 'axis-name\.json: axes\.sets: axis name "Stiff": expected' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"Stiff": [{"a": 1}]}}}'
bad axis-reserved 'axis-reserved\.json: axes\.solver_opts: axis name "status" is a built-in column name' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "solver_opts": {"status": [{"levels": 2}]}}}'
bad same-label 'same-label\.json: axes\.sets\.e\[1\]: same label "1" as axes\.sets\.e\[0\]' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"e": [{"a.E": 1}, {"b.E": 1}]}}}'
bad set-null 'set-null\.json: defaults\.set\.frames: expected a JSON value, got null' \
  '{"name": "t", "defaults": {"set": {"frames": null}}, "axes": {"scene": ["drop"], "solver": ["hot"]}}'
bad first-frame 'first-frame\.json: defaults\.first_timed_frame: expected a frame before "frames", got 3' \
  '{"name": "t", "defaults": {"frames": 3, "first_timed_frame": 3}, "axes": {"scene": ["drop"], "solver": ["hot"]}}'
bad first-scene-frames 'first-scene-frames\.json: scene "drop": first_timed_frame 400 is not before the scene.s 24 frames' \
  '{"name": "t", "defaults": {"first_timed_frame": 400, "scale": 3}, "axes": {"scene": ["drop"], "solver": ["hot"]}}'
bad malformed 'malformed\.json:1:[0-9]+: malformed JSON' '{"name": "t",, }'
# checked through the creation path of `mpmbench run`: an option the solver does not read ...
bad solver-opt 'solver-opt\.json: solver "pn-pcg" \(axes\.solver\[1\]\) with solver options levels=3 \(defaults\.solver_opts\.levels\): .*pn-pcg has no option .levels.' \
  '{"name": "t", "defaults": {"solver_opts": {"levels": 3}}, "axes": {"scene": ["drop"], "solver": ["hot", "pn-pcg"]}}'
# ... or a value the solver cannot run with
bad solver-value 'solver-value\.json: solver "hot" \(axes\.solver\[0\]\) with solver options window=100 \(axes\.solver_opts\.w\[0\]\.window\): solver option window=100: expected an integer in \[1, 64\]' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "solver_opts": {"w": [{"window": 100}]}}}'
# scenes are loaded at the cell's scale with its overrides
bad set-path 'set-path\.json: scene "drop" \(axes\.scene\[0\]\) at scale 3 with set materials\.sof\.E=5 \(axes\.sets\.e\[0\]\.materials\.sof\.E\): .*materials\.sof' \
  '{"name": "t", "defaults": {"scale": 3}, "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"e": [{"materials.sof.E": 5}]}}}'
bad set-value 'set-value\.json: scene "drop" .* with set materials\.soft\.E=-5 .*materials\.soft\.E' \
  '{"name": "t", "defaults": {"scale": 3}, "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"e": [{"materials.soft.E": -5}]}}}'
expect_input_error 'matrix run: unknown option .--frames.' matrix run "$tmp/unknown-top.json" --frames 2
expect_input_error 'unknown-top\.json: frame: unknown key' matrix run "$tmp/unknown-top.json" --check
# the accuracy and limit keys (issue 10)
bad error-ref 'error-ref\.json: defaults\.error_ref: --error-ref pn-pgc: .*unknown solver' \
  '{"name": "t", "defaults": {"error_ref": "pn-pgc"}, "axes": {"scene": ["drop"], "solver": ["hot"]}}'
bad error-ref-eps 'error-ref-eps\.json: axes\.error_ref\[1\]: --error-ref auto:-1: eps -1' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "error_ref": ["auto", "auto:-1"]}}'
bad max-outer 'max-outer\.json: defaults\.max_outer: expected an integer >= 1, got 0' \
  '{"name": "t", "defaults": {"max_outer": 0}, "axes": {"scene": ["drop"], "solver": ["hot"]}}'
bad max-step 'max-step\.json: scenes\.drop\.max_step_seconds: expected seconds in \(0, 1e9\], got -1' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"]}, "scenes": {"drop": {"max_step_seconds": -1}}}'
bad on-failure 'on-failure\.json: defaults\.on_failure: expected "stop" or "continue", got "retry"' \
  '{"name": "t", "defaults": {"on_failure": "retry"}, "axes": {"scene": ["drop"], "solver": ["hot"]}}'
bad reference-solver 'reference-solver\.json: reference\.solver: missing' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"]}, "reference": {"eps": 1e-9}}'
bad reference-key 'reference-key\.json: reference\.frames: unknown key' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"]}, "reference": {"solver": "pn-pcg", "frames": 2}}'
bad reference-false 'reference-false\.json: reference: expected an object' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"]}, "reference": false}'
bad reference-opt 'reference-opt\.json: solver "pn-pcg" \(reference\.solver\) with solver options window=4' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"]}, "reference": {"solver": "pn-pcg", "solver_opts": {"window": 4}}}'
expect_input_error '--jobs .0.: expected an integer' matrix run "$tmp/unknown-top.json" --jobs 0
expect_input_error 'no-such\.json: cannot read matrix file' matrix run "$tmp/no-such.json"
expect_input_error "matrix 'go': expected 'run', 'report' or 'schema'" matrix go

# --dry-run: the cells with ids, nothing written
mk ok "{$head, \"axes\": {\"scene\": [\"stretched-box\", \"drop\"], \"solver\": [\"hot\", \"pn-pcg\"],
        \"sets\": {\"stiff\": {\"soft\": {\"materials.soft.E\": 1e4}, \"hard\": {\"materials.soft.E\": 1e6}}}},
        \"exclude\": [{\"scene\": \"drop\", \"stiff\": \"hard\"}]}"
"$bin" matrix run "$tmp/ok.json" --dry-run --out "$tmp/dry" >"$tmp/dry.txt" 2>&1
check "dry run exit 0" test $? -eq 0
check "dry run: 6 cells, all to run" grep -q "^matrix t (.*ok.json): 6 cells, 0 done, 6 to run" "$tmp/dry.txt"
check "dry run: one line per cell" test "$(grep -cE '^[0-9a-f]{12}  todo  ' "$tmp/dry.txt")" -eq 6
check "dry run: the excluded cell is gone" bash -c "! grep -q 'drop/.*stiff=hard' '$tmp/dry.txt'"
check "dry run: labels shown" grep -q "stretched-box/pn-pcg eps=1e-07 scale=5 frames=1 stiff=hard" "$tmp/dry.txt"
check "dry run writes nothing" test ! -e "$tmp/dry"
"$bin" matrix run "$tmp/ok.json" --dry-run --out "$tmp/dry" --only 'drop/*' --only "$(grep -m1 stretched-box/hot "$tmp/dry.txt" | cut -c1-12)" >"$tmp/only.txt"
check "--only: by scene/solver glob and by id" test "$(grep -cE '^[0-9a-f]{12}  todo' "$tmp/only.txt")" -eq 3
expect_input_error "--only x\*: no cell of ok.json matches" matrix run "$tmp/ok.json" --dry-run --only 'x*'
# --threads replaces the defaults' threads (a new cell then), unless the matrix has a threads axis
"$bin" matrix run "$tmp/ok.json" --dry-run --out "$tmp/dry" --threads 3 >"$tmp/t3.txt"
check "--threads: the cells run with it" test "$(grep -c ' threads=3 ' "$tmp/t3.txt")" -eq 6
check "--threads: other ids" test -z "$(comm -12 <(cut -c1-12 "$tmp/dry.txt" | sort) <(cut -c1-12 "$tmp/t3.txt" | sort) | grep -E '^[0-9a-f]{12}$')"
mk taxis '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "threads": [1, 2]}}'
expect_input_error "--threads 3: taxis.json has a threads axis" matrix run "$tmp/taxis.json" --threads 3 --dry-run
# reference.set overrides the cell's set: every transfer is compared against one APIC reference run
mk refset '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"], "sets": {"transfer": [{"transfer": "apic"}, {"transfer": "mls"}]}},
            "reference": {"solver": "pn-cholmod", "set": {"transfer": "apic"}}}'
"$bin" matrix run "$tmp/refset.json" --dry-run --out "$tmp/dry" >"$tmp/refset.txt" 2>&1
check "reference.set: 3 cells (one reference run)" grep -q "^matrix t (.*refset.json): 3 cells, 0 done, 3 to run" "$tmp/refset.txt"
check "reference.set: the reference runs APIC" grep -q "drop/pn-cholmod eps=1e-10 .*transfer=apic (reference run)" "$tmp/refset.txt"
ref=$(grep -m1 "(reference run)" "$tmp/refset.txt" | cut -c1-12)
check "reference.set: the MLS cell is compared against it" grep -q "drop/hot .*transfer=mls reference=$ref" "$tmp/refset.txt"
bad reference-set 'reference-set\.json: reference\.set: expected an object' \
  '{"name": "t", "axes": {"scene": ["drop"], "solver": ["hot"]}, "reference": {"solver": "pn-pcg", "set": 3}}'
finish
