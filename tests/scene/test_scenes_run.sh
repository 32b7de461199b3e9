#!/usr/bin/env bash
# Every scene of the suite runs at a coarse scale (~4k particles; one frame,
# more for Boards and Sauce whose action starts later) with HOT: the smoke
# matrix (experiments/matrices/smoke.json) restricted to hot, with APIC and
# with MLS-MPM (its transfer axis, SPEC 9), every cell
# ending ok (no NaN, no particle leaving the domain) with every step
# converged to the CN tolerance. With the original meshes (optional; their
# folder in the environment variable MPM_MESH_DIR, given to
# smoke-meshes.json as --asset-dir) the mesh variants run too.
. "$(dirname "$0")/../common/shell_harness.sh"

smoke() { # matrix file, expected cell count, more matrix run options
  local name
  name=$(basename "$1" .json)
  "$bin" matrix run "$1" --only '*/hot' --out "$tmp/$name" "${@:3}" >"$tmp/$name.txt" 2>&1
  check "$name: matrix run exit 0 ($(tail -1 "$tmp/$name.txt"))" test $? -eq 0
  python3 - "$tmp/$name/cells.csv" "$2" >"$tmp/$name.check" 2>&1 <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
bad = [f"{r['scene']}/{r['solver']} {r.get('transfer', '')}: {r['status']}, {r['converged_fraction']} of {r['steps']} steps converged"
       for r in rows if r["status"] != "ok" or r["converged_fraction"] != "1.000000" or int(r["steps"]) < 1]
for b in bad:
    print("FAIL:", b)
print("ok" if not bad and len(rows) == int(sys.argv[2]) else f"{len(rows)} rows, {len(bad)} bad")
PY
  cat "$tmp/$name.check"
  check "$name: every cell ok with every step converged" test "$(tail -1 "$tmp/$name.check")" = ok
}

smoke "$src/experiments/matrices/smoke.json" 32
if [ -n "${MPM_MESH_DIR:-}" ]; then
  smoke "$src/experiments/matrices/smoke-meshes.json" 4 --asset-dir "$MPM_MESH_DIR"
else
  echo "MPM_MESH_DIR is not set: the mesh variants (smoke-meshes.json) are skipped"
fi
finish
