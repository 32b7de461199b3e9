#!/usr/bin/env bash
# One scene on this machine's 2 cores, two ways: 1 rank x 2 threads
# (OpenMP) against 2 ranks x 1 thread (mpirun, the scene split over the
# ranks: docs/distributed.md), per solver that runs across ranks: HOT
# (hot-petsc: its levels split over the ranks), projected Newton with
# block-Jacobi PCG (pn-pcg) and with PETSc's GAMG (pn-gamg-pcg), on bar3 at
# the paper's resolution (scale 1, its first frame) and on boxes at the
# 2-core benchmark scale (2.52, 50k particles; frames 0-3 are warm-up
# before the ball reaches the plates and only frame 4 is timed, as the
# baselines study times it; pn-gamg-pcg is left out there: it fails on
# boxes on one process already, results/petsc-baselines). The in-house
# hot (one process only) runs as 1 x 2 too, the reference hot-petsc's
# split is measured against (Debian's PETSc runs on one thread, so
# hot-petsc and pn-gamg-pcg thread only mpmbench's parts at 1 x 2).
# REPEATS runs of each, the configurations alternated so
# a drift of the machine hits both alike; each 2-rank run's communication
# from run.json (the busier rank's halo and collective seconds over the
# whole run, bytes sent per step).
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
echo "scene,scale,solver,ranks,threads,repeat,timed_frame,particles,steps,outer_iters,linear_iters,inner_iters,wall_s,run_wall_s,halo_s_max,collective_s_max,halo_sent_per_step_max,machine_busy,build" >"$csv"
# the build's commit, marked when its tree had uncommitted changes (then the
# number is not that commit's)
version=$("$build/mpmbench" --version | sed 's/.*git \([0-9a-f]\{7\}\)[0-9a-f]*\(, modified\)\{0,1\}.*/\1\2/; s/, modified/+modified/')
for rep in $(seq 1 "$repeats"); do
  # scene:scale:frames (the last one timed):solvers
  for case in "bar3:1:1:hot hot-petsc pn-pcg pn-gamg-pcg" "boxes:2.52:5:hot hot-petsc pn-pcg"; do
    IFS=: read -r scene scale frames solvers <<<"$case"
    for solver in $solvers; do
      configs="1x2 2x1"
      [ "$solver" = hot ] && configs=1x2 # the in-house V-cycle runs on one process only
      for config in $configs; do
        ranks=${config%x*} threads=${config#*x}
        dir=$tmp/run
        rm -rf "$dir"
        args=(run --scene "$scene" --scale "$scale" --solver "$solver" --frames "$frames" --threads "$threads" --quiet --out "$dir")
        if [ "$ranks" = 1 ]; then "$build/mpmbench" "${args[@]}" 2>/dev/null
        else mpirun --oversubscribe --allow-run-as-root --bind-to none -np "$ranks" "$build/mpmbench" "${args[@]}" --ranks "$ranks" 2>/dev/null; fi
        python3 - "$dir" "$scene" "$scale" "$solver" "$ranks" "$threads" "$rep" "$version" >>"$csv" <<'PY'
import csv, json, sys
d, scene, scale, solver, ranks, threads, rep, version = sys.argv[1:]
frames = list(csv.DictReader(open(f"{d}/frames.csv")))
f = frames[-1]  # the timed frame: the last
run_wall = sum(float(r["wall_s"]) for r in frames)  # what the communication seconds are part of
run = json.load(open(f"{d}/run.json"))
dist = run.get("distributed", {})
comm = [max(dist.get(k, [0])) for k in ("halo_seconds_per_rank", "collective_seconds_per_rank",
                                        "halo_bytes_sent_per_step_per_rank")]
print(",".join([scene, scale, solver, ranks, threads, rep, f["frame"], str(run["particles"]), f["steps"],
                f["outer_iters"], f["linear_iters"], f.get("inner_iters", "0"), f["wall_s"], f"{run_wall:.6f}"] +
               [f"{v:.6g}" for v in comm] + [str(int(run["machine_load"]["machine_busy"])), version]))
PY
        if [ -t 2 ]; then echo "repeat $rep: $scene scale $scale $solver ${ranks}x$threads done" >&2; fi
      done
    done
  done
done
python3 "$root/scripts/ranks_vs_threads.py" "$csv" >"$out/ranks-vs-threads.md"
echo "wrote $csv and $out/ranks-vs-threads.md" >&2
