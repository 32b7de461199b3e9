#!/usr/bin/env bash
# needs: MPM_WITH_PETSC
# The tests of tests/dist/ across MPI ranks, on 2 and 3 ranks, and the
# halo and step-problem tests on 4 (oversubscribed on a 2-core machine is
# fine; test_dist_solve and test_dist_steps on 4 ranks take 50 and 130 s
# here, too long for CI, and pass when run by hand): test_dist_halo (the halo
# sum and copy of a split grid through PetscSF equal the whole grid's P2G;
# a failure on one rank ends the grid's set-up on every rank with an error
# instead of a hang), test_dist_problem (a split scene's step problem:
# energy, gradient, H x, diagonal, CN residual equal the whole scene's),
# test_dist_solve (solvers across ranks: the whole scene's iterations and
# solution, or converged on the whole scene for PETSc's multigrids) and test_dist_steps (12 whole time steps
# of drop with migration: the whole scene's iterations, time steps, particle
# positions, mass and momentum).
# mpirun_ranks' timeout turns a hang into a failure.
. "$(dirname "$0")/../common/shell_harness.sh"
command -v mpirun >/dev/null || skip "mpirun not found"
for name in test_dist_halo test_dist_problem test_dist_hierarchy test_dist_solve test_dist_steps; do
  helper="$(dirname "$bin")/tests/$name"
  [ -x "$helper" ] || { echo "FAIL: $helper not built"; fails=$((fails + 1)); continue; }
  ranks_list="2 3"
  case $name in test_dist_halo | test_dist_problem) ranks_list="2 3 4" ;; esac
  for ranks in $ranks_list; do
    out="$tmp/$name.$ranks"
    mpirun_ranks -np $ranks "$helper" >"$out" 2>&1
    rc=$?
    check "$name on $ranks ranks: exit 0 ($(grep -c 'check failed' "$out") failed checks; exit $rc)" test $rc -eq 0
    check "$name on $ranks ranks: every rank reports" test "$(grep -c ' 0 failed$' "$out")" -eq $ranks
    [ $rc -eq 0 ] || head -20 "$out"
  done
done
finish
