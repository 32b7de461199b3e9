#!/usr/bin/env bash
# needs: MPM_WITH_PETSC
# tests/dist/test_dist_halo.c across MPI ranks: the halo sum and copy of a
# split grid through PetscSF equal the whole grid's P2G on 2 and 3 ranks
# (oversubscribed on a 2-core machine is fine), and a failure on one rank
# ends the grid's set-up on every rank with an error instead of a hang
# (mpirun_ranks' timeout turns a hang into a failure).
. "$(dirname "$0")/../common/shell_harness.sh"
command -v mpirun >/dev/null || skip "mpirun not found"
helper="$(dirname "$bin")/tests/test_dist_halo"
[ -x "$helper" ] || { echo "FAIL: $helper not built"; exit 1; }
for ranks in 2 3; do
  mpirun_ranks -np $ranks "$helper" >"$tmp/out$ranks" 2>&1
  rc=$?
  check "$ranks ranks: exit 0 ($(grep -c 'check failed' "$tmp/out$ranks") failed checks; exit $rc)" test $rc -eq 0
  check "$ranks ranks: every rank reports" test "$(grep -c ' 0 failed$' "$tmp/out$ranks")" -eq $ranks
  [ $rc -eq 0 ] || head -20 "$tmp/out$ranks"
done
finish
