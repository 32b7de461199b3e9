#!/usr/bin/env bash
# `matrix run --check` decides from the cells' files (experiments/
# matrix_check.h): nine cells are run, then all but one are altered the way
# a broken solver or run would leave them, and the verdicts are checked one
# by one: a converged step whose residual is not below eps, an accepted
# energy increase, a NaN in frames.csv, a cell killed at the wall-clock limit,
# a crash, an internal error, a reported particle escape (passes), a run
# that stopped early without a reason, and an unknown status. --check exits
# 3 with one line, prints each failing cell, writes check.csv, and the
# report shows the grid.
. "$(dirname "$0")/../common/shell_harness.sh"

cat >"$tmp/m.json" <<'EOF'
{"name": "chk", "defaults": {"scene": "drop", "scale": 3, "frames": 2, "threads": 1, "solver": "pn-pcg"},
 "axes": {"sets": {"k": {"ok": {"materials.soft.E": 1.0e5}, "residual": {"materials.soft.E": 1.1e5},
                         "rise": {"materials.soft.E": 1.2e5}, "nan": {"materials.soft.E": 1.3e5},
                         "killed": {"materials.soft.E": 1.4e5}, "crash": {"materials.soft.E": 1.5e5},
                         "internal": {"materials.soft.E": 1.6e5}, "escape": {"materials.soft.E": 1.7e5},
                         "short": {"materials.soft.E": 1.8e5}, "status": {"materials.soft.E": 1.9e5}}}}}
EOF
"$bin" matrix run "$tmp/m.json" --out "$tmp/r" --check >"$tmp/first.txt" 2>&1
check "untouched: every cell passes, exit 0" test $? -eq 0
check "untouched: the summary" grep -q "^check: 10 of 10 cells passed" "$tmp/first.txt"

ids=$(python3 - "$tmp/r/cells.csv" <<'PY'
import csv, sys
print(" ".join(f"{r['k']}={r['id']}" for r in csv.DictReader(open(sys.argv[1]))))
PY
)
for kv in $ids; do eval "id_${kv%%=*}=${kv#*=}"; done
d="$tmp/r/cells"
# edit CSV $1: set column $2 of row $3 (0-based; -1 = last) to $4; or drop rows after $3 with $2 = "--cut"
edit() {
  python3 - "$@" <<'PY'
import csv, sys
path, col, row, val = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
rows = list(csv.reader(open(path)))
if col == "--cut":
    rows = rows[:row + 2]
else:
    rows[1:][row][rows[0].index(col)] = val
csv.writer(open(path, "w", newline="")).writerows(rows)
PY
}
cells_row() { # id column value: edit that cell's cells.csv row
  python3 - "$tmp/r/cells.csv" "$@" <<'PY'
import csv, sys
path, cid, col, val = sys.argv[1:]
rows = list(csv.reader(open(path)))
for r in rows[1:]:
    if r[0] == cid:
        r[rows[0].index(col)] = val
csv.writer(open(path, "w", newline="")).writerows(rows)
PY
}
edit "$d/$id_residual/steps.csv" residual 0 2.000000e-07
edit "$d/$id_rise/steps.csv" max_energy_rise -1 3.5e-09
edit "$d/$id_nan/frames.csv" wall_s 0 nan
cells_row "$id_killed" status timeout
cells_row "$id_crash" status crashed
cells_row "$id_crash" exit -11
cells_row "$id_internal" status failed
cells_row "$id_internal" exit 1
echo "mpmbench: error: out of memory: grid velocities" >"$d/$id_internal/stderr.txt"
cells_row "$id_escape" status failed
cells_row "$id_escape" exit 1
echo "mpmbench: error: particle 12 at (0.5, -0.3, 0.5) left the domain or became non-finite at t = 0.1 s" >"$d/$id_escape/stderr.txt"
edit "$d/$id_short/frames.csv" --cut 0 x
edit "$d/$id_status/steps.csv" status 0 exploded

"$bin" matrix run "$tmp/m.json" --out "$tmp/r" --check >"$tmp/out.txt" 2>"$tmp/err.txt"
check "altered: exit 3 (cells failed their check)" test $? -eq 3
check "altered: one error line naming the count" test "$(wc -l <"$tmp/err.txt")" -eq 1 -a \
  "$(grep -c 'matrix run --check: 8 of 10 cells failed' "$tmp/err.txt")" -eq 1
check "altered: nothing rerun" grep -q "10 done already, 0 to run" "$tmp/out.txt"
verdict() { # id: "pass|reasons" from check.csv
  python3 - "$tmp/r/check.csv" "$1" <<'PY'
import csv, sys
for r in csv.DictReader(open(sys.argv[1])):
    if r["id"] == sys.argv[2]:
        print(r["pass"] + "|" + r["reasons"])
PY
}
expect() { # name id pass pattern
  local v
  v=$(verdict "$2")
  check "$1: ${v}" bash -c "[[ '${v%%|*}' == '$3' ]] && grep -qE -- '$4' <<<'${v#*|}'"
}
expect ok "$id_ok" 1 '^$'
expect "residual above eps" "$id_residual" 0 'frame 0 step 0: status converged but residual 2.000000e-07 is not below eps 1e-07'
expect "energy rise" "$id_rise" 0 'a line search accepted an energy increase of 3.5e-09'
expect "NaN" "$id_nan" 0 'frames.csv row 1: wall_s = nan'
expect "killed" "$id_killed" 0 'killed at the wall-clock limit'
expect "crash" "$id_crash" 0 'crashed \(signal 11\)'
expect "internal error" "$id_internal" 0 'exit 1: mpmbench: error: out of memory'
expect "reported escape passes" "$id_escape" 1 'reported: .*left the domain'
expect "stopped early" "$id_short" 0 'ran 1 of 2 frames and its last step \(converged\) says nothing of why'
expect "unknown status" "$id_status" 0 'unknown status "exploded"'
check "every failing cell printed" test "$(grep -c '^check: FAIL ' "$tmp/out.txt")" -eq 8
check "the check.csv header" grep -qx "id,scene,solver,eps,k,pass,reasons" "$tmp/r/check.csv"

"$bin" matrix report "$tmp/r" >/dev/null 2>"$tmp/rep.err"
rc=$?  # before the description's $(...), which resets $?
check "report: exit 0 ($(head -c 200 "$tmp/rep.err"))" test $rc -eq 0
check "report: grid row of a failing case" grep -q "^| drop k=rise | \*\*FAIL\*\* |$" "$tmp/r/report.md"
check "report: grid row of a passing case" grep -q "^| drop k=ok | pass |$" "$tmp/r/report.md"
check "report: passed per solver" grep -q "^| \*\*passed\*\* | 2/10 |$" "$tmp/r/report.md"
check "report: the reasons listed" grep -q "^- drop k=nan / pn-pcg ($id_nan): frames.csv row 1: wall_s = nan" "$tmp/r/report.md"
finish
