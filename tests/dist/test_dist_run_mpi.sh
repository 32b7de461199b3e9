#!/usr/bin/env bash
# needs: MPM_WITH_PETSC
# `mpirun -np R mpmbench run` splits the scene over the R ranks
# (docs/distributed.md): bar3 (scale 4, 2 frames) with pn-pcg-mf,
# lbfgs:jacobi and pn-pcg (assembled) on 2 and 3 ranks gives the
# one-process run's rows of steps.csv (frame, step, t, dt, particles,
# active nodes, outer and linear iterations, line-search evaluations,
# status) exactly and its residuals to 1e-6; with pn-gamg-pcg (PETSc's GAMG
# on the parallel matrix: its aggregates differ with the split) every step
# converges, the steps and particles are the one-process run's, and each
# step's outer iterations are within 2 of it. Rank 0 alone writes the
# folder, and run.json records the ranks and each rank's particles, which
# add up, and its halo traffic (the bytes sent add up to those received). Options that follow one trajectory are refused with exit 2 on
# every rank, and so is a solver whose inverse has no form across ranks.
. "$(dirname "$0")/../common/shell_harness.sh"
command -v mpirun >/dev/null || skip "mpirun not found"
R=(run --scene bar3 --scale 4 --frames 2 --threads 1 --quiet)
compare() { # serial distributed ranks exact(1|0)
  python3 - "$@" <<'PY'
import csv, json, sys
a, b, ranks, same = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4] == "1"
ra, rb = list(csv.DictReader(open(f"{a}/steps.csv"))), list(csv.DictReader(open(f"{b}/steps.csv")))
assert len(ra) == len(rb) > 0, (len(ra), len(rb))
exact = ["frame", "step", "t", "dt", "particles", "active_nodes", "outer_iters", "linear_iters", "ls_evals", "status"]
if not same:
    exact = ["frame", "step", "particles", "status"]
for x, y in zip(ra, rb):
    d = [k for k in exact if x[k] != y[k]]
    assert not d, (x["frame"], x["step"], [(k, x[k], y[k]) for k in d])
    if same:
        assert abs(float(x["residual"]) - float(y["residual"])) <= 1e-6 * float(x["residual"]), (x["residual"], y["residual"])
    else:
        assert y["status"] == "converged" and abs(int(x["outer_iters"]) - int(y["outer_iters"])) <= 2, (x["step"], x["outer_iters"], y["outer_iters"])
        assert abs(float(x["dt"]) - float(y["dt"])) <= 1e-6 * float(x["dt"]), (x["dt"], y["dt"])
dist = json.load(open(f"{b}/run.json"))["distributed"]
assert dist["ranks"] == ranks and len(dist["particles_per_rank"]) == ranks, dist
assert sum(dist["particles_per_rank"]) == int(ra[-1]["particles"]), dist
assert min(dist["particles_per_rank"]) > 0, dist
# every byte a rank sends in the halo another receives; every rank takes part in every halo operation and collective
sent, received = sum(dist["halo_bytes_sent_per_rank"]), sum(dist["halo_bytes_received_per_rank"])
assert sent == received > 0, (sent, received)
assert len(set(dist["halo_ops_per_rank"])) == 1 and dist["halo_ops_per_rank"][0] > 0, dist["halo_ops_per_rank"]
assert len(set(dist["collectives_per_rank"])) == 1 and dist["collectives_per_rank"][0] > 0, dist["collectives_per_rank"]
assert all(s >= 0 for s in dist["halo_seconds_per_rank"] + dist["collective_seconds_per_rank"]), dist
print("ok")
PY
}
for solver in pn-pcg-mf lbfgs:jacobi pn-pcg pn-gamg-pcg; do
  name=${solver%%:*}
  same=1
  [ "$solver" = pn-gamg-pcg ] && same=0
  "$bin" "${R[@]}" --solver "$solver" --out "$tmp/$name-1"
  check "$solver on one process: exit 0" test $? -eq 0
  for ranks in 2 3; do
    mpirun_ranks -np $ranks "$bin" "${R[@]}" --solver "$solver" --out "$tmp/$name-$ranks" >"$tmp/out" 2>&1
    rc=$?  # before the description's $(...), which resets $?
    check "$solver on $ranks ranks: exit 0 ($(head -c 300 "$tmp/out"))" test $rc -eq 0
    compare "$tmp/$name-1" "$tmp/$name-$ranks" $ranks $same >"$tmp/cmp" 2>&1
    check "$solver on $ranks ranks: the one-process rows ($(tail -1 "$tmp/cmp"))" grep -qx ok "$tmp/cmp"
  done
done
mpirun_ranks -np 2 "$bin" "${R[@]}" --solver pn-pcg-mf --vtk "$tmp/vtk" --out "$tmp/bad" >"$tmp/out" 2>&1
rc=$?
check "--vtk over ranks: exit 2 ($rc), refused on every rank" test $rc -eq 2 -a "$(grep -c '^mpmbench: error: --vtk: not in a run over MPI ranks yet' "$tmp/out")" -eq 2
mpirun_ranks -np 2 "$bin" "${R[@]}" --solver pn-sgs-pcg --out "$tmp/asm" >"$tmp/out" 2>&1
rc=$?
check "a solver without a form across ranks: exit 2 ($rc), one line per rank" test $rc -eq 2 -a "$(grep -c '^mpmbench: error: .*has no form across ranks' "$tmp/out")" -eq 2
finish
