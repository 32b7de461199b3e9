# Sourced by tests/scene/test_scenes_run.sh and test_scenes_mesh.sh (after
# shell_harness.sh): smoke FILE N [matrix run options] runs FILE's HOT cells
# and checks that there are N, each ending ok with every step converged.
smoke() { # matrix file, expected cell count, more matrix run options
  local name
  name=$(basename "$1" .json)
  "$bin" matrix run "$1" --only '*/hot' --out "$tmp/$name" "${@:3}" >"$tmp/$name.txt" 2>&1
  rc=$?  # before the description's $(...), which resets $?
  check "$name: matrix run exit 0 ($(tail -1 "$tmp/$name.txt"))" test $rc -eq 0
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
