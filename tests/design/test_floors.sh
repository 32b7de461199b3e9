#!/usr/bin/env bash
# The floors of docs/design.md hold in the sources (scripts/check_includes.py
# passes on the tree), and the check catches each kind of breach: a copy of
# the sources gets one bad #include at a time and the check must fail naming
# it. Tests too: each names its floor ("/* floor: core */") and includes
# nothing above it (tests/CMakeLists.txt links it against that floor only).
. "$(dirname "$0")/../common/shell_harness.sh"
checker="$src/scripts/check_includes.py"

python3 "$checker" "$src" >"$tmp/tree.out" 2>&1
rc=$?
check "the source tree keeps its floors (exit $rc): $(head -3 "$tmp/tree.out")" test "$rc" -eq 0

# a pristine copy of the sources, restored before each breach
mkdir -p "$tmp/pristine"
(cd "$src" && cp -r core solvers adapters experiments "$tmp/pristine/" &&
  mkdir -p "$tmp/pristine/tests" "$tmp/pristine/docs" && cp -r tests/common tests/unit tests/conformance tests/fuzz "$tmp/pristine/tests/" &&
  cp -r docs/examples "$tmp/pristine/docs/")

# breach FILE LINE PATTERN: FILE gets LINE appended; the check must exit 1
# with a line matching PATTERN
breach() {
  local file="$1" line="$2" pattern="$3"
  rm -rf "$tmp/copy" && cp -r "$tmp/pristine" "$tmp/copy"
  printf '%s\n' "$line" >>"$tmp/copy/$file"
  python3 "$checker" "$tmp/copy" >"$tmp/out" 2>&1
  local rc=$?
  checks=$((checks + 1))
  if [ "$rc" -ne 1 ] || ! grep -qE -e "$pattern" "$tmp/out"; then
    echo "FAIL: '$line' in $file: exit $rc, $(head -3 "$tmp/out")  [wanted /$pattern/]"
    fails=$((fails + 1))
  fi
}

breach core/vec.c '#include "solvers/solver.h"' 'core/vec.c:[0-9]+: includes "solvers/solver.h": the core part'
breach core/grid.c '#include "core/scene/scene_load.h"' 'the core part may use only core$'
breach core/grid.c '#include <jansson.h>' 'core/grid.c:[0-9]+: includes <jansson.h>, a third-party header'
breach solvers/inverse/jacobi.c '#include "adapters/ml.h"' 'the solvers part may use only'
breach solvers/mg/mg.c '#include "experiments/driver/registry.h"' 'the solvers part may use only'
breach adapters/ml.c '#include "adapters/cholmod.h"' 'an adapter sees no other adapter'
breach experiments/driver/session.c '#include "experiments/run/run.h"' 'the driver part may use only'
breach experiments/driver/frame_driver.c '#include <jansson.h>' 'third-party header the driver part'
breach experiments/run/provenance.c '#include "adapters/boomeramg.h"' 'the run part may use only'
breach experiments/matrix/matrix_run.c '#include "experiments/commands/commands.h"' 'the matrix part may use only'
breach experiments/render/render.c '#include <mpi.h>' 'third-party header the render part'
# tests: a test (or test helper) includes no header above the floor its floor line names
breach tests/unit/test_svd.c '#include "solvers/solver.h"' 'tests/unit/test_svd.c:[0-9]+: includes "solvers/solver.h": a test of the core floor'
breach tests/unit/test_pcg.c '#include "experiments/driver/registry.h"' 'a test of the solvers floor may use only core, solvers$'
breach tests/unit/test_problem.c '#include "tests/common/scene_fixture.h"' 'includes "tests/common/scene_fixture.h": a test of the core floor'
breach tests/common/fixture.h '#include "core/scene/scene_load.h"' 'tests/common/fixture.h:[0-9]+: .*a test of the core floor'
breach tests/unit/test_svd.c '#include "mpm_adapters_built.h"' 'includes "mpm_adapters_built.h": a test of the core floor'
# a test without its floor line
rm -rf "$tmp/copy" && cp -r "$tmp/pristine" "$tmp/copy"
sed -i '/^\/\* floor: /d' "$tmp/copy/tests/unit/test_svd.c"
python3 "$checker" "$tmp/copy" >"$tmp/out" 2>&1
check "a test without a floor line is found: $(head -3 "$tmp/out")" grep -q '^tests/unit/test_svd.c: no "/\* floor: ' "$tmp/out"
# a circle of modules: csv_table includes paths and paths includes csv_table
rm -rf "$tmp/copy" && cp -r "$tmp/pristine" "$tmp/copy"
echo '#include "experiments/io/csv_table.h"' >>"$tmp/copy/experiments/io/paths.h"
echo '#include "experiments/io/paths.h"' >>"$tmp/copy/experiments/io/csv_table.h"
python3 "$checker" "$tmp/copy" >"$tmp/out" 2>&1
rc=$?
check "a circle of modules is found (exit $rc): $(cat "$tmp/out")" \
  grep -qE 'in a circle: experiments/io/csv_table -> experiments/io/paths -> experiments/io/csv_table' "$tmp/out"
finish
