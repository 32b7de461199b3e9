#!/usr/bin/env bash
# HOT Fig. 20 stiffness sweep: the three-segment bar (scene bar3) with the
# middle segment's Young's modulus E swept over several decades, run with
# several solvers; then a summary table (scripts/summarize.py).
#
# usage: scripts/bench_stiffness.sh [--scale S] [--frames F] [--threads T]
#            [--solvers "a b c"] [--E "1e5 1e7"] [--out DIR] [--bin PATH]
#            [--baseline NAME] [--timeout SECONDS] [--summary-only]
#
# Every flag has an environment variable of the same meaning (the flag wins):
#   SCALE=1.86          --scale     dx multiplier (1.86: about 50k particles)
#   FRAMES=5            --frames    frames per run (the scene has 48)
#   THREADS=2           --threads   OpenMP threads per run
#   SOLVERS="hot pn-pcg pn-pcg-mf pn-mgpcg lbfgs-h"
#                       --solvers   solvers missing from `mpmbench list
#                                   solvers` are skipped with a warning
#   E_VALUES="1e5 1e7 1e9 1e11"
#                       --E         middle-segment moduli [Pa]
#   OUT=results/stiffness --out     result tree: OUT/<E>/<solver>/ holds each
#                                   run's frames.csv, steps.csv, run.json
#   MPMBENCH=build/mpmbench --bin   the binary (relative paths: from the
#                                   repository root)
#   BASELINE=pn-pcg     --baseline  solver the time ratios refer to
#   TIMEOUT=0           --timeout   seconds per run, 0 = none (coreutils
#                                   timeout; a cut run shows as incomplete)
#
# Resumable: a cell whose frames.csv already has F rows (and whose run.json
# has the same scale) is skipped, so an interrupted sweep continues where it
# stopped; delete a cell's directory to redo it. A run that fails is
# reported and the sweep goes on; its cell shows as incomplete.
#
# Output: OUT/summary.csv and a Markdown table on stdout (per E and solver:
# total wall s, s/frame, outer and linear iterations, steps, worst status,
# time ratio to the baseline and speedup of each solver over it).
set -u
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

scale=${SCALE:-1.86}
frames=${FRAMES:-5}
threads=${THREADS:-2}
solvers=${SOLVERS:-"hot pn-pcg pn-pcg-mf pn-mgpcg lbfgs-h"}
evalues=${E_VALUES:-"1e5 1e7 1e9 1e11"}
out=${OUT:-results/stiffness}
bin=${MPMBENCH:-build/mpmbench}
baseline=${BASELINE:-pn-pcg}
timeout_s=${TIMEOUT:-0}
summary_only=0

die() { echo "bench_stiffness: $*" >&2; exit 2; }

while [ $# -gt 0 ]; do
  case "$1" in
    --scale) scale=${2:?--scale: missing value}; shift 2 ;;
    --frames) frames=${2:?--frames: missing value}; shift 2 ;;
    --threads) threads=${2:?--threads: missing value}; shift 2 ;;
    --solvers) solvers=${2:?--solvers: missing value}; shift 2 ;;
    --E) evalues=${2:?--E: missing value}; shift 2 ;;
    --out) out=${2:?--out: missing value}; shift 2 ;;
    --bin) bin=${2:?--bin: missing value}; shift 2 ;;
    --baseline) baseline=${2:?--baseline: missing value}; shift 2 ;;
    --timeout) timeout_s=${2:?--timeout: missing value}; shift 2 ;;
    --summary-only) summary_only=1; shift ;;
    -h|--help) sed -n '2,/^set -u/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) die "unknown option '$1' (see --help)" ;;
  esac
done

case "$frames" in ''|*[!0-9]*|0) die "--frames '$frames': expected a positive integer" ;; esac
case "$threads" in ''|*[!0-9]*|0) die "--threads '$threads': expected a positive integer" ;; esac
case "$timeout_s" in ''|*[!0-9]*) die "--timeout '$timeout_s': expected seconds (0 = none)" ;; esac
case "$bin" in /*) ;; *) bin="$root/$bin" ;; esac
case "$out" in /*) ;; *) out="$root/$out" ;; esac
[ -x "$bin" ] || die "$bin: no mpmbench binary (build first, or set MPMBENCH / --bin)"

# solvers the binary knows
known=$("$bin" list solvers | awk '{print $1}') || die "$bin list solvers failed"
run_solvers=()
for s in $solvers; do
  if printf '%s\n' "$known" | grep -qxF -- "$s"; then
    run_solvers+=("$s")
  else
    echo "bench_stiffness: warning: solver '$s' is not in '$(basename "$bin") list solvers': skipped" >&2
  fi
done
[ ${#run_solvers[@]} -gt 0 ] || die "no solver to run"

# complete DIR: frames.csv has $frames rows and run.json the same scale
complete() {
  local dir="$1"
  [ -f "$dir/frames.csv" ] && [ -f "$dir/run.json" ] || return 1
  local rows
  rows=$(($(wc -l <"$dir/frames.csv") - 1))
  [ "$rows" -ge "$frames" ] || return 1
  python3 - "$dir/run.json" "$scale" <<'PY'
import json, sys
try:
    run = json.load(open(sys.argv[1]))
    sys.exit(0 if abs(float(run["scale"]) - float(sys.argv[2])) <= 1e-6 * float(sys.argv[2]) else 1)
except (OSError, ValueError, KeyError):
    sys.exit(1)
PY
}

dirs=()
n_cells=0
for E in $evalues; do n_cells=$((n_cells + ${#run_solvers[@]})); done
cell=0
failed=0
for E in $evalues; do
  for s in "${run_solvers[@]}"; do
    cell=$((cell + 1))
    dir="$out/$E/$s"
    dirs+=("$dir")
    [ "$summary_only" -eq 1 ] && continue
    if complete "$dir"; then
      echo "[$cell/$n_cells] E=$E $s: done already, skipped"
      continue
    fi
    echo -n "[$cell/$n_cells] E=$E $s: running ... "
    mkdir -p "$dir"
    cmd=("$bin" run --scene bar3 --solver "$s" --scale "$scale" --frames "$frames" --threads "$threads"
         --quiet --set "materials.middle.E=$E" --out "$dir")
    [ "$timeout_s" -gt 0 ] && cmd=(timeout "$timeout_s" "${cmd[@]}")
    t0=$(date +%s.%N)
    "${cmd[@]}" >"$dir/log.txt" 2>&1
    rc=$?
    t1=$(date +%s.%N)
    secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.1f", b - a}')
    if [ "$rc" -eq 0 ]; then
      echo "${secs} s"
    else
      failed=$((failed + 1))
      [ "$rc" -eq 124 ] && why="timed out after ${timeout_s} s" || why="exit $rc: $(tail -n 1 "$dir/log.txt")"
      echo "FAILED (${why})"
    fi
  done
done
[ "$failed" -gt 0 ] && echo "bench_stiffness: warning: $failed run(s) failed; their cells show as incomplete" >&2

present=()
for d in "${dirs[@]}"; do [ -f "$d/frames.csv" ] && present+=("$d"); done
[ ${#present[@]} -gt 0 ] || die "no results under $out"
echo
python3 "$root/scripts/summarize.py" --baseline "$baseline" --csv "$out/summary.csv" "${present[@]}"
