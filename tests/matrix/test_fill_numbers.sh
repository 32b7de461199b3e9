#!/usr/bin/env bash
# The numbers quoted in README.md, results/README.md and docs/*.md are those
# of the committed results: scripts/fill_numbers.py --check finds no stale
# or unknown marker. It also fails on a marker whose text was typed by hand
# (a wrong value) and on an unknown key, so the check can fail.
. "$(dirname "$0")/../common/shell_harness.sh"
fill="$src/scripts/fill_numbers.py"
python3 "$fill" --check >"$tmp/out" 2>&1
rc=$?
checks=$((checks + 1))
if [ $rc -ne 0 ]; then echo "FAIL: quoted numbers differ from the results:"; cat "$tmp/out"; fails=$((fails + 1)); fi
good=$(python3 "$fill" --list | sed -n 's/^stress.passed: //p')
check "the key stress.passed has a value" test -n "$good"
printf 'x <!-- n:stress.passed -->%s<!-- /n --> y\n' "$good" >"$tmp/right.md"
check "a right value passes" python3 "$fill" --check "$tmp/right.md"
printf 'x <!-- n:stress.passed -->193 of 192<!-- /n --> y\n' >"$tmp/wrong.md"
check "a wrong value fails" bash -c "! python3 '$fill' --check '$tmp/wrong.md' 2>/dev/null"
printf 'x <!-- n:no.such.key -->1<!-- /n --> y\n' >"$tmp/unknown.md"
check "an unknown key fails" bash -c "! python3 '$fill' --check '$tmp/unknown.md' 2>/dev/null"
finish
