#!/usr/bin/env bash
# needs: MPM_WITH_PETSC
# The petsc inverse approximation from the command line (docs/solvers.md,
# "petsc options"): a PETSc option PETSc did not use (a typo, an option of
# another PC), one PETSc refuses (an unknown type, a non-number) and one that
# prints are each one line on stderr and exit 2, before any output; the
# presets run, and run.json records PETSc's version, the options given with
# the two defaults, and PETSc's own KSPView of the last setup; hot-petsc
# (HOT's hierarchy as a PCMG) takes the in-house HOT's iterations step by step.
. "$(dirname "$0")/../common/shell_harness.sh"
export OMP_NUM_THREADS=1
run=(run --scene bar3 --scale 6 --frames 1 --quiet)

expect_input_error "pc_gamg_thresold=0.02: PETSc did not use it" "${run[@]}" --out "$tmp/x1" \
  --solver pn:petsc:pc_gamg_thresold=0.02
expect_input_error "pc_gamg_threshold=0.02: PETSc did not use it with ksp_type=preonly, pc_type=jacobi" "${run[@]}" \
  --out "$tmp/x2" --solver pn:petsc:pc_type=jacobi,pc_gamg_threshold=0.02
# the preset's own GAMG options are not used by another PC either
expect_input_error "pc_gamg_agg_nsmooths=0: PETSc did not use it with ksp_type=preonly, pc_type=hypre" "${run[@]}" \
  --out "$tmp/x3" --solver pn-gamg-pcg:pc_type=hypre
expect_input_error "pc_type=nosuch.*Unable to find requested PC type nosuch" "${run[@]}" --out "$tmp/x4" \
  --solver pn:petsc:pc_type=nosuch
expect_input_error "pc_gamg_threshold=abc.*no numeric value" "${run[@]}" --out "$tmp/x5" \
  --solver pn:petsc:pc_gamg_threshold=abc
expect_input_error "ksp_monitor: PETSc options that print" "${run[@]}" --out "$tmp/x6" --solver pn:petsc:ksp_monitor=1
expect_input_error "petsc_rbm=maybe: expected on or off" "${run[@]}" --out "$tmp/x7" --solver lbfgs-gamg:petsc_rbm=maybe
# HOT's hierarchy: its options exist only with it, and it sets the smoothers itself
expect_input_error "petsc_levels=3: pn:petsc:petsc_levels=3 has no option 'petsc_levels'" "${run[@]}" --out "$tmp/x8" \
  --solver pn:petsc:petsc_levels=3
expect_input_error "mg_levels_ksp_type: petsc_hierarchy sets the smoothers itself" "${run[@]}" --out "$tmp/x9" \
  --solver hot-petsc:mg_levels_ksp_type=chebyshev
for d in x1 x2 x3 x4 x5 x6 x7 x8 x9; do
  check "refused before any output ($d)" test ! -e "$tmp/$d"
done

for s in pn-gamg-pcg lbfgs-gamg; do
  "$bin" "${run[@]}" --solver $s --out "$tmp/$s" >"$tmp/$s.log" 2>&1
  rc=$?  # before the description's $(...), which resets $?
  check "$s runs: exit 0 ($(tail -1 "$tmp/$s.log"))" test $rc -eq 0
done
python3 - "$tmp/pn-gamg-pcg" >"$tmp/json.txt" 2>&1 <<'PY'
import csv, json, sys
d = sys.argv[1]
r = json.load(open(f"{d}/run.json"))
assert r["provenance"]["libraries"]["petsc"].startswith("3."), r["provenance"]["libraries"]
o = r["solver_options"]
assert o["ksp_type"] == "preonly" and o["pc_type"] == "gamg" and o["pc_gamg_agg_nsmooths"] == "0", o
assert o["mg_levels_ksp_type"] == "chebyshev" and o["petsc_rbm"] == "on", o
v = r["inverse_view"]
assert "type: gamg" in v and "type: chebyshev" in v and "type: jacobi" in v, v[:400]
steps = list(csv.DictReader(open(f"{d}/steps.csv")))
assert all(s["status"] == "converged" for s in steps), [s["status"] for s in steps]
assert sum(int(s["linear_iters"]) for s in steps) > 0
print("ok")
PY
check "run.json: PETSc's version, the options with their defaults, PETSc's KSPView ($(tail -1 "$tmp/json.txt"))" \
  grep -qx ok "$tmp/json.txt"
# hot-petsc is HOT's V-cycle run by PETSc: on the same steps it takes the
# in-house double-precision HOT's iterations, inner (coarse CG) iterations
# and line-search evaluations, step by step
hot=(run --scene bar3 --scale 3 --frames 2 --quiet)
"$bin" "${hot[@]}" --solver hot-petsc --out "$tmp/hot-petsc" >"$tmp/hp.log" 2>&1
rc=$?  # before the description's $(...), which resets $?
check "hot-petsc runs: exit 0 ($(tail -1 "$tmp/hp.log"))" test $rc -eq 0
"$bin" "${hot[@]}" --solver hot:smoother_precision=double --out "$tmp/hot" >"$tmp/h.log" 2>&1
rc=$?  # before the description's $(...), which resets $?
check "hot (double) runs: exit 0 ($(tail -1 "$tmp/h.log"))" test $rc -eq 0
python3 - "$tmp/hot-petsc" "$tmp/hot" >"$tmp/agree.txt" 2>&1 <<'PY'
import csv, sys
a, b = (list(csv.DictReader(open(f"{d}/steps.csv"))) for d in sys.argv[1:3])
assert len(a) == len(b) and len(a) >= 4, (len(a), len(b))
for x, y in zip(a, b):
    for k in ("outer_iters", "inner_iters", "ls_evals", "status", "dt"):
        assert x[k] == y[k], (k, x["frame"], x["step"], x[k], y[k])
print("ok: %d steps, %d outer and %d inner iterations on both" % (len(a), sum(int(s["outer_iters"]) for s in a),
                                                                  sum(int(s["inner_iters"]) for s in a)))
PY
check "hot-petsc and hot take the same iterations step by step ($(tail -1 "$tmp/agree.txt"))" grep -q "^ok" "$tmp/agree.txt"
finish
