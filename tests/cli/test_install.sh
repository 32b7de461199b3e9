#!/usr/bin/env bash
# An installed copy (cmake --install BUILD --prefix DIR: DIR/bin/mpmbench,
# DIR/share/mpmbench/{scenes,matrices,scripts}) works from a folder outside
# any checkout with no MPM_* variable: it lists and runs the built-in scenes,
# finds a built-in matrix by name, runs a matrix and writes its report with
# the installed scripts, and records the working directory's checkout. No
# path of the source or build tree is in the binary, and the build tree
# links share/mpmbench to the source folders (core/scene/data_dir.h).
. "$(dirname "$0")/../common/shell_harness.sh"
build=$(cd "$(dirname "$bin")" && pwd)
srcabs=$(cd "$src" && pwd)

check "no source path in the binary: $(grep -aoF "$srcabs" "$bin" | head -1)" bash -c "! grep -qaF '$srcabs' '$bin'"
check "no build path in the binary" bash -c "! grep -qaF '$build' '$bin'"
for pair in scenes:experiments/scenes matrices:experiments/matrices scripts:scripts; do
  check "the build tree's share/mpmbench/${pair%%:*} is the source's ${pair#*:}" \
    test "$(readlink -f "$build/share/mpmbench/${pair%%:*}")" = "$(readlink -f "$src/${pair#*:}")"
done

cmake --install "$build" --prefix "$tmp/inst" >"$tmp/install.txt" 2>&1
rc=$?  # before the description's $(...), which resets $?
check "cmake --install exit 0 ($(tail -1 "$tmp/install.txt"))" test $rc -eq 0
inst="$tmp/inst/bin/mpmbench"
mkdir -p "$tmp/elsewhere"
cd "$tmp/elsewhere" || exit 1
unset MPM_SCENE_DIR MPM_SCRIPT_DIR
export GIT_CEILING_DIRECTORIES="$tmp" # $tmp may lie inside a checkout: git must not look above it

"$inst" list scenes >"$tmp/scenes.txt" 2>&1
rc=$?  # before the description's $(...), which resets $?
check "list scenes exit 0 ($(head -1 "$tmp/scenes.txt"))" test $rc -eq 0
n_src=$(find "$src/experiments/scenes" -maxdepth 1 -name '*.json' | wc -l)
check "list scenes: the $n_src built-in scenes" test "$(grep -c '^[a-z]' "$tmp/scenes.txt")" -eq "$n_src"

"$inst" run --scene drop --solver pn-pcg --scale 4 --frames 1 --quiet --out "$tmp/elsewhere/run" 2>"$tmp/run.err"
rc=$?  # before the description's $(...), which resets $?
check "run --scene drop exit 0 ($(head -c 200 "$tmp/run.err"))" test $rc -eq 0
check "run --scene drop: steps.csv" test -s "$tmp/elsewhere/run/steps.csv"

"$inst" matrix run smoke --dry-run >"$tmp/dry.txt" 2>&1
check "matrix run smoke (a built-in matrix by name): $(head -c 200 "$tmp/dry.txt")" \
  grep -qF "$tmp/inst/share/mpmbench/matrices/smoke.json" "$tmp/dry.txt"

cat >"$tmp/tiny.json" <<'EOF'
{"name": "tiny", "description": "two solvers on drop, one coarse frame", "defaults": {"frames": 1, "scale": 4},
 "axes": {"scene": ["drop"], "solver": ["pn-pcg", "hot"]}, "baseline": "pn-pcg"}
EOF
"$inst" matrix run "$tmp/tiny.json" --out "$tmp/m" >"$tmp/m.txt" 2>&1
rc=$?  # before the description's $(...), which resets $?
check "matrix run exit 0 ($(tail -1 "$tmp/m.txt"))" test $rc -eq 0
check "provenance: the checkout of the working directory (none here)" python3 -c "
import json, sys
c = json.load(open(sys.argv[1]))['invocations'][0]['checkout']
sys.exit(not (c['commit'].startswith('unknown') and c['path'] == sys.argv[2]))" "$tmp/m/provenance.json" "$tmp/elsewhere"
"$inst" matrix report "$tmp/m" >"$tmp/report.txt" 2>&1
rc=$?  # before the description's $(...), which resets $?
check "matrix report with the installed scripts exit 0 ($(tail -1 "$tmp/report.txt"))" test $rc -eq 0
check "matrix report: report.md" test -s "$tmp/m/report.md"
check "the installed scripts write no __pycache__" test -z "$(find "$tmp/inst" -name __pycache__)"
finish
