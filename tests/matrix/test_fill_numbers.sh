#!/usr/bin/env bash
# The numbers quoted in README.md, results/README.md, docs/*.md and the study
# pages are those of the committed results: scripts/fill_numbers.py --check
# finds no stale or unknown marker. It also fails on a marker whose text was
# typed by hand (a wrong value) and on an unknown key, so the check can fail.
# Trust (issue 28): every committed study is judged by this build
# (MPM_BINARY); a number from a study that is not current, from busy cells or,
# for a ranking, from one run per cell cannot be quoted as current (n:), only
# as history (h:) beside its study's status (s:).
. "$(dirname "$0")/../common/shell_harness.sh"
fill="$src/scripts/fill_numbers.py"
export MPM_BINARY="$bin"
python3 "$fill" --check >"$tmp/out" 2>&1
rc=$?
checks=$((checks + 1))
if [ $rc -ne 0 ]; then echo "FAIL: quoted numbers differ from the results:"; cat "$tmp/out"; fails=$((fails + 1)); fi
good=$(python3 "$fill" --list | sed -n 's/^stress.date: //p')
check "the key stress.date has a value" test -n "$good"
printf 'x <!-- n:stress.date -->%s<!-- /n --> y\n' "$good" >"$tmp/right.md"
check "a right value passes" python3 "$fill" --check "$tmp/right.md"
printf 'x <!-- n:stress.date -->2026-12-31<!-- /n --> y\n' >"$tmp/wrong.md"
check "a wrong value fails" bash -c "! python3 '$fill' --check '$tmp/wrong.md' 2>/dev/null"
printf 'x <!-- n:no.such.key -->1<!-- /n --> y\n' >"$tmp/unknown.md"
check "an unknown key fails" bash -c "! python3 '$fill' --check '$tmp/unknown.md' 2>/dev/null"

# --- trust ---
# stiffness is stale for this build (its status line says so)
stale_val=$(python3 "$fill" --list | sed -n 's/^stiffness.hot_geomean: \([^ ]*\) .*/\1/p')
check "stiffness.hot_geomean has a value ($stale_val)" test -n "$stale_val"
printf '# A\n\nx <!-- n:stiffness.hot_geomean -->%s<!-- /n --> y\n' "$stale_val" >"$tmp/n-stale.md"
python3 "$fill" --check "$tmp/n-stale.md" 2>"$tmp/n-stale.err"
check "a stale study's number quoted as current fails" test $? -ne 0
check "... saying to quote it as history" grep -q "not a current number.*quote it as history" "$tmp/n-stale.err"
printf '# A\n\nx <!-- h:stiffness.hot_geomean -->%s<!-- /n --> y\n' "$stale_val" >"$tmp/h-bare.md"
python3 "$fill" --check "$tmp/h-bare.md" 2>"$tmp/h-bare.err"
check "history without its study's status in the section fails" test $? -ne 0
check "... naming the status marker" grep -q "s:stiffness -->) is not in its section" "$tmp/h-bare.err"
st=$(python3 -c "import sys; sys.path.insert(0, '$src/scripts'); import fill_numbers as f; print(f.status_text('stiffness'))")
check "the status line names build, runs and staleness ($st)" bash -c "echo '$st' | grep -q 'stiffness: build [0-9a-f]\{7\}.*1 run per cell.*stale for .*kept for history'"
printf '# A\n\nx <!-- h:stiffness.hot_geomean -->%s<!-- /n --> y\n\n## B\n\n- <!-- s:stiffness -->%s<!-- /n -->\n\n# C\n' "$stale_val" "$st" >"$tmp/h-ok.md"
check "history with its study's status in its section (a subsection) passes" python3 "$fill" --check "$tmp/h-ok.md"
printf '# A\n\nx <!-- h:stiffness.hot_geomean -->%s<!-- /n --> y\n\n# B\n\n- <!-- s:stiffness -->%s<!-- /n -->\n' "$stale_val" "$st" >"$tmp/h-far.md"
check "the status in another section does not count" bash -c "! python3 '$fill' --check '$tmp/h-far.md' 2>/dev/null"
printf '# A\n\n- <!-- s:stiffness -->build 1<!-- /n -->\n' >"$tmp/s-typed.md"
check "a status typed by hand fails" bash -c "! python3 '$fill' --check '$tmp/s-typed.md' 2>/dev/null"
date_val=$(python3 "$fill" --list | sed -n 's/^stiffness.date: //p')
printf '# A\n\n<!-- h:stiffness.date -->%s<!-- /n -->\n\n- <!-- s:stiffness -->%s<!-- /n -->\n' "$date_val" "$st" >"$tmp/h-current.md"
check "a study's date quoted as history fails (it describes, it is current)" bash -c "! python3 '$fill' --check '$tmp/h-current.md' 2>/dev/null"
# scenes-bench is current (this build's definitions, 3 runs a cell, quiet): its ranking quoted as current passes
cur_val=$(python3 "$fill" --list | sed -n 's/^scenes.hot_geomean: \([^ ]*\).*/\1/p')
printf '# A\n\nx <!-- n:scenes.hot_geomean -->%s<!-- /n --> y\n' "$cur_val" >"$tmp/n-current.md"
check "a current study's ranking quoted as current passes ($cur_val)" python3 "$fill" --check "$tmp/n-current.md"
# the rules themselves, on made-up statuses: current, busy, one run
python3 - "$src/scripts" <<'PY' >"$tmp/rules.out" 2>&1
import sys
sys.path.insert(0, sys.argv[1])
import fill_numbers as f
base = {"current": True, "busy_cells": 0, "repeats": 3, "stale_solvers": []}
f._status.update({"good": dict(base), "stale": dict(base, current=False), "busy": dict(base, busy_cells=1),
                  "once": dict(base, repeats=1)})
rank, plain = "scenes.hot_geomean", "wp.err_h_range_at_1e-7"
assert rank in f.RANKING and plain not in f.RANKING and "scenes.cells" not in f.RANKING
assert f.doubts(rank, {"good"}) == [], "current, quiet, repeated: a current number"
assert f.doubts(rank, {"good", "stale"}), "one stale study is enough"
assert f.doubts(plain, {"busy"}), "busy cells"
assert f.doubts(rank, {"once"}) and not f.doubts(plain, {"once"}), "one run: refused for a ranking only"
assert f.doubts("scenes.date", {"stale"}) == [], "a date describes the study"
row = lambda t, lo, hi, n: {"s_per_frame": t, "s_per_frame_min": lo, "s_per_frame_max": hi, "runs": n}
assert f.clearly_faster(row(1.0, 0.9, 1.1, 3), row(1.5, 1.2, 1.6, 3)), "ranges apart: faster"
assert not f.clearly_faster(row(1.0, 0.9, 1.3, 3), row(1.5, 1.2, 1.6, 3)), "ranges overlap: a tie, whatever the medians"
assert not f.clearly_faster(row(1.0, 1.0, 1.0, 1), row(1.05, 1.05, 1.05, 1)), "single runs: within the 1.1x floor"
assert f.clearly_faster(row(1.0, 1.0, 1.0, 1), row(1.2, 1.2, 1.2, 1)), "single runs: beyond it"
print("rules ok")
PY
check "trust rules on made-up statuses ($(tail -1 "$tmp/rules.out"))" grep -qx "rules ok" "$tmp/rules.out"
# a stale study's page says so on its first line
page="$src/results/stiffness/report.md"
check "stiffness's page opens with its status" bash -c "head -1 '$page' | grep -q '^> <!-- s:stiffness -->'"
finish
