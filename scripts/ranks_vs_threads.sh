#!/usr/bin/env bash
# One scene on this machine's 2 cores, two ways: 1 rank x 2 threads
# (OpenMP) against 2 ranks x 1 thread (mpirun, the scene split over the
# ranks: docs/distributed.md), for the solvers that run across ranks
# (pn-pcg-mf, lbfgs:jacobi), on bar3 at the paper's resolution (scale 1)
# and at the 2-core benchmark scale (scale 2). REPEATS runs of each, the
# configurations alternated so a drift of the machine hits both alike.
# Run it alone on the machine. Writes results/distributed/ranks-vs-threads.csv
# (one row per run) and ranks-vs-threads.md (scripts/ranks_vs_threads.py).
#
#   scripts/ranks_vs_threads.sh [BUILD_DIR] [REPEATS]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
repeats=${2:-3}
out=$root/results/distributed
mkdir -p "$out"
csv=$out/ranks-vs-threads.csv
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "scene,scale,solver,ranks,threads,repeat,particles,steps,outer_iters,linear_iters,wall_s,machine_busy,build" >"$csv"
version=$("$build/mpmbench" --version | sed 's/.*git \([0-9a-f]\{7\}\).*/\1/')
for rep in $(seq 1 "$repeats"); do
  for scale in 1 2; do
    for solver in pn-pcg-mf lbfgs:jacobi; do
      for config in 1x2 2x1; do
        ranks=${config%x*} threads=${config#*x}
        dir=$tmp/run
        rm -rf "$dir"
        args=(run --scene bar3 --scale "$scale" --solver "$solver" --frames 1 --threads "$threads" --quiet --out "$dir")
        if [ "$ranks" = 1 ]; then "$build/mpmbench" "${args[@]}" 2>/dev/null
        else mpirun --oversubscribe --allow-run-as-root -np "$ranks" "$build/mpmbench" "${args[@]}" 2>/dev/null; fi
        python3 - "$dir" bar3 "$scale" "$solver" "$ranks" "$threads" "$rep" "$version" >>"$csv" <<'PY'
import csv, json, sys
d, scene, scale, solver, ranks, threads, rep, version = sys.argv[1:]
f = list(csv.DictReader(open(f"{d}/frames.csv")))[0]
run = json.load(open(f"{d}/run.json"))
print(",".join([scene, scale, solver, ranks, threads, rep, str(run["particles"]), f["steps"], f["outer_iters"],
                f["linear_iters"], f["wall_s"], str(int(run["machine_load"]["machine_busy"])), version]))
PY
        echo "repeat $rep: bar3 scale $scale $solver ${ranks}x$threads done" >&2
      done
    done
  done
done
python3 "$root/scripts/ranks_vs_threads.py" "$csv" >"$out/ranks-vs-threads.md"
echo "wrote $csv and $out/ranks-vs-threads.md" >&2
