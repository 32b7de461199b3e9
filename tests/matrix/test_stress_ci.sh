#!/usr/bin/env bash
# The reduced stress suite (experiments/matrices/stress-ci.json, issue 10):
# the stress cases at a coarse scale with the four fastest presets, run with
# `matrix run --check`. The program must never crash or hang on them: every
# cell passes the check (exit 0), check.csv has a verdict per cell and the
# report shows the pass/fail grid.
. "$(dirname "$0")/../common/shell_harness.sh"

m="$src/experiments/matrices/stress-ci.json"
"$bin" matrix run "$m" --out "$tmp/s" --jobs 2 --check >"$tmp/out.txt" 2>"$tmp/err.txt"
rc=$?
check "stress-ci --check: exit 0 ($(grep -c '^check: FAIL' "$tmp/out.txt") failing cells: $(grep '^check: FAIL' "$tmp/out.txt" | head -5))" test $rc -eq 0
n=$("$bin" matrix run "$m" --out "$tmp/s" --dry-run | head -1 | sed 's/.*: \([0-9]*\) cells.*/\1/')
check "a row per cell ($n)" test "$(($(wc -l <"$tmp/s/cells.csv") - 1))" -eq "$n"
check "a verdict per cell, all pass" test "$(tail -n +2 "$tmp/s/check.csv" | grep -c ',1,[^,]*$')" -eq "$n"
# (time-limit: the run stopped itself at max_run_seconds and said so, on a loaded machine)
check "every cell ended ok (no crash, no kill)" python3 -c "
import csv, sys; sys.exit(not {r['status'] for r in csv.DictReader(open('$tmp/s/cells.csv'))} <= {'ok', 'time-limit'})"
check "the summary line" grep -q "^check: $n of $n cells passed" "$tmp/out.txt"
"$bin" matrix report "$tmp/s" >/dev/null 2>"$tmp/rep.err"
rc=$?  # before the description's $(...), which resets $?
check "report: exit 0 ($(head -c 200 "$tmp/rep.err"))" test $rc -eq 0
check "report: the robustness grid" grep -q "^### Robustness (matrix run --check)" "$tmp/s/report.md"
check "report: the robustness answer first" test "$(sed -n 3p "$tmp/s/report.md" | cut -c1-14)" = "- Robustness: "
check "report: passed per solver" grep -q "^| \*\*passed\*\* | 24/24 | 24/24 | 24/24 | 24/24 |" "$tmp/s/report.md"
check "report: the grid figure" test -s "$tmp/s/figures/robustness.png"
finish
