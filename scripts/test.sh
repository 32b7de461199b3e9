#!/usr/bin/env bash
# The test command (CI runs exactly this, via .ci/run):
#   1. setup (packages + build/) and the whole CTest suite;
#   2. the unit tests again in an ASan + UBSan build (build-asan: any
#      address error, leak or undefined behaviour fails the test);
#   3. each libFuzzer target for MPM_FUZZ_SECONDS (default 60) seconds.
# Extra arguments go to the first ctest. MPM_QUICK=1 runs step 1 only.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
# what only the tests need: VTK's Python reader (tests/cli/test_vtk.sh reads the ParaView output back)
if ! dpkg-query -W -f='${Status}' python3-vtk9 2>/dev/null | grep -q "install ok installed"; then
  echo "test.sh: installing python3-vtk9" >&2
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends python3-vtk9 >/dev/null
fi
t0=$SECONDS
ctest --test-dir build --output-on-failure -j2 "$@"
echo "test.sh: release suite $((SECONDS - t0)) s" >&2
[ "${MPM_QUICK:-0}" = 1 ] && exit 0

# --- 2. sanitizers ---------------------------------------------------------
# Tests too slow under ASan for CI's budget are listed here (and printed),
# never dropped silently; they still run in step 1.
asan_skip=${MPM_ASAN_SKIP-"test_solvers|test_mg_scene"} # 385 s and 141 s alone under ASan (release: 52 s, 32 s);
# the multigrid code runs under ASan in test_mg and test_conformance
t0=$SECONDS
# the default compiler (gcc): a clang build with libFuzzer's coverage
# instrumentation runs these tests 2-3x slower, and libomp leaks its thread
# teams when the thread count changes (test_robust), so the fuzz targets of
# step 3 get their own build (build-fuzz)
if [ ! -f build-asan/CMakeCache.txt ]; then
  cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMPM_SANITIZE=ON >/dev/null
fi
log=build-asan/build.log
if ! nice -n 5 cmake --build build-asan -j"$(nproc)" -- --no-print-directory >"$log" 2>&1; then
  cat "$log" >&2
  echo "test.sh: sanitizer build failed (log: $log)" >&2
  exit 1
fi
# MPI (through the hypre adapter) leaks internals at start-up and shutdown:
# suppressed by call stack through MPI's init/finalize only (the file says why)
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_string_checks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizer/lsan.supp:fast_unwind_on_malloc=0:print_suppressions=0"
echo "test.sh: ASan+UBSan unit tests (not run under ASan, too slow for CI: ${asan_skip:-none})" >&2
ctest --test-dir build-asan --output-on-failure -j2 -E "^(${asan_skip:-none}|test_cli|test_render_cmd|test_scenes_run|test_summarize)\$"
echo "test.sh: sanitizer suite $((SECONDS - t0)) s" >&2

# --- 3. fuzzing ------------------------------------------------------------
t0=$SECONDS
bash scripts/fuzz.sh all "${MPM_FUZZ_SECONDS:-60}"
echo "test.sh: fuzzing $((SECONDS - t0)) s" >&2
