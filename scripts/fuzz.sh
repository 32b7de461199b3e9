#!/usr/bin/env bash
# Coverage-guided fuzzing of one loader with libFuzzer + ASan + UBSan:
#   scripts/fuzz.sh TARGET SECONDS      TARGET: scene | obj | set | matrix | all
# Builds $MPM_FUZZ_BUILD (default build-fuzz) with clang (-DMPM_FUZZ=ON,
# configured once), then runs fuzz/fuzz_TARGET there for SECONDS on one core
# (nice; with `all`, one target per core at a time), starting from the seed corpus tests/fuzz/corpus/TARGET (plus what
# earlier runs found, in BUILD/corpus/TARGET) with tests/fuzz/TARGET.dict.
# A crash, leak, sanitizer report or timeout exits non-zero and leaves the
# input in BUILD/crashes/TARGET/: copy it to tests/fuzz/regressions/TARGET/
# once fixed, and the normal build's CTest test fuzz_replay_TARGET replays
# it from then on. Prints one line per target: executions and crashes.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -ne 2 ] || ! [[ "$2" =~ ^[0-9]+$ ]]; then
  echo "usage: scripts/fuzz.sh scene|obj|set|matrix|all SECONDS" >&2
  exit 2
fi
what="$1" seconds="$2"
targets=()
if [ "$what" = all ]; then
  for f in tests/fuzz/fuzz_*.c; do t=$(basename "$f" .c); targets+=("${t#fuzz_}"); done
else
  [ -f "tests/fuzz/fuzz_$what.c" ] || { echo "fuzz.sh: no harness tests/fuzz/fuzz_$what.c" >&2; exit 2; }
  targets=("$what")
fi
command -v clang >/dev/null || { echo "fuzz.sh: needs clang (scripts/test.sh installs it)" >&2; exit 2; }

build=${MPM_FUZZ_BUILD:-build-fuzz}
# PETSc off, as in the sanitizer build (scripts/test.sh): a fuzzed matrix
# naming a PETSc preset would start PETSc, whose refused options leak inside it
if [ ! -f "$build/CMakeCache.txt" ]; then
  CC=clang cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMPM_FUZZ=ON -DBUILD_TESTING=OFF \
    -DMPM_WITH_PETSC=OFF >/dev/null
else
  cmake -S . -B "$build" -DMPM_WITH_PETSC=OFF >/dev/null # picks up a harness added since (fuzz_*.c glob)
fi
for t in "${targets[@]}"; do
  nice -n 10 cmake --build "$build" -j"$(nproc)" --target "fuzz_$t" -- --no-print-directory >"$build/fuzz-build.log" 2>&1 ||
    { cat "$build/fuzz-build.log" >&2; exit 1; }
done

export OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:abort_on_error=1:allocator_may_return_null=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
# one target per core at a time (libFuzzer itself runs on one core)
fuzz_one() {
  local t=$1 corpus=$build/corpus/$1 crashes=$build/crashes/$1 log=$build/fuzz-$1.log rc
  mkdir -p "$corpus" "$crashes"
  local dict=()
  [ -f "tests/fuzz/$t.dict" ] && dict=(-dict="tests/fuzz/$t.dict")
  set +e
  nice -n 10 "$build/fuzz/fuzz_$t" "$corpus" "tests/fuzz/corpus/$t" "${dict[@]}" \
    -max_total_time="$seconds" -timeout=20 -rss_limit_mb=3072 -max_len=65536 \
    -artifact_prefix="$crashes/" -print_final_stats=1 >"$log" 2>&1
  rc=$?
  set -e
  local execs ncrash nslow
  execs=$(grep -E "^stat::number_of_executed_units" "$log" | tail -1 | awk '{print $2}')
  ncrash=$(find "$crashes" -type f \( -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' \) | wc -l)
  nslow=$(find "$crashes" -type f -name 'slow-unit-*' | wc -l)
  echo "fuzz $t: ${execs:-0} executions in $seconds s, exit $rc, $ncrash crash/leak/timeout/oom inputs ($nslow slow) in $crashes (log $log)"
  if [ "$rc" -ne 0 ]; then
    grep -m5 -E "ERROR|runtime error|SUMMARY|without a one-line|outside|abort" "$log" >&2 || tail -20 "$log" >&2
    return 1
  fi
}
status=0 cores=$(nproc) pids=()
for t in "${targets[@]}"; do
  fuzz_one "$t" &
  pids+=($!)
  if [ "${#pids[@]}" -ge "$cores" ]; then
    wait "${pids[0]}" || status=1
    pids=("${pids[@]:1}")
  fi
done
for p in "${pids[@]}"; do wait "$p" || status=1; done
exit $status
