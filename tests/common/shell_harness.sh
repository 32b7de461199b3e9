# Shared by the tests/test_*.sh CLI tests (sourced, not a test itself):
# `bin` and `src` from the arguments CTest passes, a scratch directory `tmp`
# removed at exit (kept with KEEP_TMP=1, to look into a failure), and the checks below counting into `checks` / `fails`;
# a test ends with `finish`.
set -u
bin="$1"
src="$2"
tmp=$(mktemp -d)
trap '[ -n "${KEEP_TMP:-}" ] || rm -rf "$tmp"' EXIT
fails=0
checks=0

# `matrix report` runs MPM_PYTHON, else the python3 on PATH. When that one has
# no matplotlib (a pyenv or virtual-environment python3 first on PATH) and
# Debian's /usr/bin/python3 has it, the report tests use Debian's.
if [ -z "${MPM_PYTHON:-}" ] && ! python3 -c 'import matplotlib' 2>/dev/null &&
  /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
  export MPM_PYTHON=/usr/bin/python3
fi

check() { # description, condition-command...
  local what="$1"; shift
  checks=$((checks + 1))
  if ! "$@"; then echo "FAIL: $what"; fails=$((fails + 1)); fi
}

# expect_input_error <pattern> <mpmbench args...>: exit 2 and exactly one
# stderr line matching pattern
expect_input_error() {
  local pattern="$1"; shift
  "$bin" "$@" >"$tmp/out" 2>"$tmp/err"
  local rc=$?
  checks=$((checks + 1))
  local lines
  lines=$(wc -l <"$tmp/err")
  if [ "$rc" -ne 2 ] || [ "$lines" -ne 1 ] || ! grep -qiE -e "$pattern" "$tmp/err"; then
    echo "FAIL: '$*' gave exit $rc, stderr ($lines lines): $(cat "$tmp/err")  [wanted /$pattern/]"
    fails=$((fails + 1))
  fi
}

# skip <why>: the test cannot run here (a tool or file it needs is missing):
# exit 77, which CTest reports as "Skipped" (tests/CMakeLists.txt), never as
# passed
skip() {
  echo "SKIPPED: $*"
  exit 77
}

finish() {
  echo "$((checks - fails)) passed, $fails failed"
  if [ "$checks" -eq 0 ]; then echo "FAIL: no checks ran"; return 1; fi
  [ "$fails" -eq 0 ]
}

# mpirun for the distributed matrix tests. In the sanitizer build the ranks
# keep ASan/UBSan's halt on error but not LeakSanitizer: under mpirun Open MPI
# unloads its MCA components before LSan reports, so their start-up
# allocations (dozens) show unknown frames no suppression can name. The same
# runner code is leak-checked by the serial matrix tests.
mpirun_ranks() {
  ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:detect_leaks=0} timeout 180 \
    mpirun --oversubscribe --allow-run-as-root "$@"
}
