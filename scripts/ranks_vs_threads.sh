#!/usr/bin/env bash
# One scene on this machine's 2 cores, two ways: 1 rank x 2 threads
# (OpenMP) against 2 ranks x 1 thread (mpirun, the scene split over the
# ranks: docs/distributed.md), for the solvers that run across ranks
# (pn-pcg-mf, lbfgs:jacobi, pn-pcg, pn-gamg-pcg), on bar3 at the paper's
# resolution (scale 1) and at the 2-core benchmark scale (scale 2). Not
# boxes: its first frames come before the ball touches the plates (a
# timed frame needs warm-up frames, which this script does not skip), and
# pn-gamg-pcg fails on it on one process already (results/petsc-baselines).
# REPEATS runs of each, the configurations alternated so
# a drift of the machine hits both alike; each 2-rank run's communication
# from run.json (the busier rank's halo and collective seconds, bytes sent
# per step).
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
echo "scene,scale,solver,ranks,threads,repeat,particles,steps,outer_iters,linear_iters,wall_s,halo_s_max,collective_s_max,halo_sent_per_step_max,machine_busy,build" >"$csv"
# the build's commit, marked when its tree had uncommitted changes (then the
# number is not that commit's)
version=$("$build/mpmbench" --version | sed 's/.*git \([0-9a-f]\{7\}\)[0-9a-f]*\(, modified\)\{0,1\}.*/\1\2/; s/, modified/+modified/')
for rep in $(seq 1 "$repeats"); do
  for case in bar3:1 bar3:2; do
    scene=${case%:*} scale=${case#*:}
    for solver in pn-pcg-mf lbfgs:jacobi pn-pcg pn-gamg-pcg; do
      for config in 1x2 2x1; do
        ranks=${config%x*} threads=${config#*x}
        dir=$tmp/run
        rm -rf "$dir"
        args=(run --scene "$scene" --scale "$scale" --solver "$solver" --frames 1 --threads "$threads" --quiet --out "$dir")
        if [ "$ranks" = 1 ]; then "$build/mpmbench" "${args[@]}" 2>/dev/null
        else mpirun --oversubscribe --allow-run-as-root -np "$ranks" "$build/mpmbench" "${args[@]}" 2>/dev/null; fi
        python3 - "$dir" "$scene" "$scale" "$solver" "$ranks" "$threads" "$rep" "$version" >>"$csv" <<'PY'
import csv, json, sys
d, scene, scale, solver, ranks, threads, rep, version = sys.argv[1:]
f = list(csv.DictReader(open(f"{d}/frames.csv")))[0]
run = json.load(open(f"{d}/run.json"))
dist = run.get("distributed", {})
comm = [max(dist.get(k, [0])) for k in ("halo_seconds_per_rank", "collective_seconds_per_rank",
                                        "halo_bytes_sent_per_step_per_rank")]
print(",".join([scene, scale, solver, ranks, threads, rep, str(run["particles"]), f["steps"], f["outer_iters"],
                f["linear_iters"], f["wall_s"]] + [f"{v:.6g}" for v in comm] +
               [str(int(run["machine_load"]["machine_busy"])), version]))
PY
        if [ -t 2 ]; then echo "repeat $rep: $scene scale $scale $solver ${ranks}x$threads done" >&2; fi
      done
    done
  done
done
python3 "$root/scripts/ranks_vs_threads.py" "$csv" >"$out/ranks-vs-threads.md"
echo "wrote $csv and $out/ranks-vs-threads.md" >&2
