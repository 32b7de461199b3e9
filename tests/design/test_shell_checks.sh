#!/usr/bin/env bash
# The shell tests' exit-status checks can fail: in
#   check "ran ($(tail -1 log))" test $? -eq 0
# the description's command substitution runs first and sets $? to its own
# status (0), so the check passed whatever the command returned (27 checks
# did, until a run that hung and was killed by its timeout passed). The
# status must be taken first (rc=$?). This scans every test script for the
# pattern, and shows on a sample that bash behaves so.
. "$(dirname "$0")/../common/shell_harness.sh"

grep -rnE --include='*.sh' '^[[:space:]]*check ".*\$\(.*(test|\[) +"?\$\?' "$src/tests" "$src/scripts" >"$tmp/hits" 2>/dev/null
check "no check reads \$? after a command substitution ($(head -3 "$tmp/hits"))" test ! -s "$tmp/hits"
# the hazard itself: after `false`, $? read after a substitution in the same command is 0
false
probe() { echo "$2"; }
check "bash resets \$? in a command substitution (the reason for this test)" test "$(false; probe "$(true)" $?)" = 0
finish
