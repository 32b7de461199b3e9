#!/usr/bin/env bash
# How should OpenMP's idle threads wait? HOT on bar3 (scale 2, about 40k
# particles, 2 threads, 3 frames, the first untimed) under four wait
# settings, alternated, on an idle machine and beside one process spinning
# on one core:
#   omp_default  libgomp's own (MPM_KEEP_OMP_WAIT=1: mpmbench leaves it alone)
#   spin10k      GOMP_SPINCOUNT=10000
#   spin1k       GOMP_SPINCOUNT=1000 (mpmbench's default, omp_wait.h)
#   passive      OMP_WAIT_POLICY=passive
#
#   scripts/omp_wait_study.sh OUT [REPS]     (REPS: default 5)
#
# OUT/runs.csv: load, wait, repeat, s_per_frame (the timed frames' mean),
# machine_busy and others_cpu_s (run.json machine_load), dir; OUT/runs/N/
# each run's run.json and frames.csv. An idle run that finds the machine
# busy is run again (up to 10 times; only the last is kept);
# scripts/fill_numbers.py quotes the medians of the idle runs and of the
# runs beside the spinner (whose machine_busy is the point).
# Environment: MPMBENCH (default build-native/mpmbench).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:?usage: scripts/omp_wait_study.sh OUT [REPS]}
reps=${2:-5}
bin=${MPMBENCH:-build-native/mpmbench}
mkdir -p "$out/runs"
echo "load,wait,repeat,s_per_frame,machine_busy,others_cpu_s,dir" >"$out/runs.csv"
args=(run --scene bar3 --scale 2 --solver hot --frames 3 --threads 2 --quiet)
n=0
one() { # load wait repeat
  local dir="$out/runs/$n" env_args
  case $2 in
    omp_default) env_args=(MPM_KEEP_OMP_WAIT=1) ;;
    spin10k) env_args=(GOMP_SPINCOUNT=10000) ;;
    spin1k) env_args=(GOMP_SPINCOUNT=1000) ;;
    passive) env_args=(OMP_WAIT_POLICY=passive) ;;
  esac
  rm -rf "$dir.tmp"
  env -u OMP_WAIT_POLICY -u GOMP_SPINCOUNT "${env_args[@]}" "$bin" "${args[@]}" --out "$dir.tmp" >/dev/null 2>&1
  mkdir -p "$dir"
  cp "$dir.tmp/run.json" "$dir.tmp/frames.csv" "$dir/"
  rm -rf "$dir.tmp"
  python3 - "$1" "$2" "$3" "$dir" >>"$out/runs.csv" <<'PY'
import csv, json, sys
load, wait, rep, d = sys.argv[1:]
rows = list(csv.DictReader(open(d + "/frames.csv")))[1:]
m = json.load(open(d + "/run.json"))["machine_load"]
print(f"{load},{wait},{rep},{sum(float(r['wall_s']) for r in rows) / len(rows):.4f},{int(m['machine_busy'])},"
      f"{m['others_cpu_s']:.3f},runs/{d.rsplit('/', 1)[1]}")
PY
  n=$((n + 1))
}
waits=(omp_default spin10k spin1k passive)
for r in $(seq "$reps"); do
  for w in "${waits[@]}"; do
    for try in $(seq 10); do
      one idle "$w" "$r"
      [ "$(tail -1 "$out/runs.csv" | cut -d, -f5)" = 0 ] && break
      [ "$try" = 10 ] && break # kept, flagged busy: the study then cannot be quoted as current
      sed -i '$d' "$out/runs.csv" # an idle run that was not: run it again
      sleep 10
    done
  done
done
(while :; do :; done) &
spinner=$!
trap 'kill $spinner 2>/dev/null' EXIT
for r in $(seq "$reps"); do
  for w in "${waits[@]}"; do one one-core-busy "$w" "$r"; done
done
echo "omp_wait_study.sh: $n runs in $out/runs.csv"
