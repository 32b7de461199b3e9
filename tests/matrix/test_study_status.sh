#!/usr/bin/env bash
# scripts/study_status.py tells a current study from a stale one:
#  - it recomputes a run's definition hash from outer_method,
#    inverse_approximation and solver_options exactly as the C code forms it
#    (the hash run.json records), for a preset and for a composed spec with
#    options;
#  - a fresh two-cell matrix is current; the same study with one run.json
#    edited to an older option value (as an old build would have recorded
#    it) is stale for that solver and only that one;
#  - repeats and busy cells are counted from cells.csv.
. "$(dirname "$0")/../common/shell_harness.sh"
cat >"$tmp/m.json" <<'JSON'
{"name": "status", "defaults": {"scene": "drop", "scale": 3, "frames": 1},
 "axes": {"solver": ["pn-pcg", "hot:window=4"]}, "repeat": 2}
JSON
"$bin" matrix run "$tmp/m.json" --out "$tmp/res" >"$tmp/run.txt" 2>&1
rc=$?  # before the description's $(...), which resets $?
check "matrix run ($(tail -2 "$tmp/run.txt"))" test $rc -eq 0
python3 - "$src/scripts" "$tmp/res" <<'PY' >"$tmp/hash.txt" 2>&1
import csv, json, os, sys
sys.path.insert(0, sys.argv[1])
import study_status as s
res = sys.argv[2]
for c in csv.DictReader(open(os.path.join(res, "cells.csv"))):
    run = json.load(open(os.path.join(res, "cells", c["id"], "run.json")))
    text, h = run.pop("solver_definition"), run.pop("solver_definition_hash")
    assert s.definition(run) == text, (c["solver"], s.definition(run), text)
    assert s.fnv1a64(text) == h, (c["solver"], s.fnv1a64(text), h)
print("ok")
PY
check "Python recomputes the C definition and hash ($(tail -3 "$tmp/hash.txt"))" grep -qx ok "$tmp/hash.txt"
status() { python3 "$src/scripts/study_status.py" --binary "$bin" --json "$1" | python3 -c "import json,sys; s=json.load(sys.stdin)[0]; print(eval(sys.argv[1]))" "$2"; }
check "a fresh study is current" test "$(status "$tmp/res" 's["current"]')" = True
check "repeats 2" test "$(status "$tmp/res" 's["repeats"]')" = 2
check "busy cells counted from cells.csv" test "$(status "$tmp/res" 's["busy_cells"]')" = \
  "$(python3 -c 'import csv,sys; print(sum(r["machine_busy"] == "1" for r in csv.DictReader(open(sys.argv[1]))))' "$tmp/res/cells.csv")"
# an old build's record: no definition fields, window=8 where the spec now gives 4
cp -r "$tmp/res" "$tmp/old"
id=$(python3 -c 'import csv,sys; print([r["id"] for r in csv.DictReader(open(sys.argv[1])) if r["solver"].startswith("hot")][0])' "$tmp/old/cells.csv")
python3 - "$tmp/old/cells/$id/run.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
del r["solver_definition"], r["solver_definition_hash"]
r["solver_options"]["window"] = "8"
json.dump(r, open(sys.argv[1], "w"))
PY
check "an older option value makes the study stale for that solver only" \
  test "$(status "$tmp/old" 's["stale_solvers"]')" = "['hot:window=4']"
finish
