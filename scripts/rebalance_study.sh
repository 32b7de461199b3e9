#!/usr/bin/env bash
# Does cutting the grid again pay? drop (a soft box falling onto the
# ground: its particles leave the blocks of the first cut) at scale 0.5
# (55k particles), its whole animation (24 frames), on 2 ranks x 1 thread,
# with --rebalance-above 0 (the first cut kept), 1.2 (the default) and
# 1.05. REPEATS runs of each, the settings alternated so a drift of the
# machine hits all alike; from each run's run.json the new cuts, the worst
# imbalance, the particles each rank ended with and the particles that
# migrated, and from frames.csv the seconds of the animation.
# Run it alone on the machine. Writes results/distributed/rebalance.csv
# (one row per run) and rebalance.md (scripts/rebalance_study.py).
#
#   scripts/rebalance_study.sh [BUILD_DIR] [REPEATS]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
repeats=${2:-3}
out=$root/results/distributed
mkdir -p "$out"
csv=$out/rebalance.csv
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "scene,scale,solver,ranks,threads,rebalance_above,repeat,particles,frames,steps,outer_iters,linear_iters,wall_s,recuts,worst_imbalance,end_imbalance,particles_sent,machine_busy,build" >"$csv"
# the build's commit, marked when its tree had uncommitted changes (then the
# number is not that commit's)
version=$("$build/mpmbench" --version | sed 's/.*git \([0-9a-f]\{7\}\)[0-9a-f]*\(, modified\)\{0,1\}.*/\1\2/; s/, modified/+modified/')
scene=drop scale=0.5 solver=pn-pcg
for rep in $(seq 1 "$repeats"); do
  for above in 0 1.2 1.05; do
    dir=$tmp/run
    rm -rf "$dir"
    mpirun --oversubscribe --allow-run-as-root -np 2 "$build/mpmbench" run --scene "$scene" --scale "$scale" \
      --solver "$solver" --threads 1 --rebalance-above "$above" --quiet --out "$dir" 2>/dev/null
    python3 - "$dir" "$scene" "$scale" "$solver" "$above" "$rep" "$version" >>"$csv" <<'PY'
import csv, json, sys
d, scene, scale, solver, above, rep, version = sys.argv[1:]
frames = list(csv.DictReader(open(f"{d}/frames.csv")))
run = json.load(open(f"{d}/run.json"))
dist = run["distributed"]
parts = dist["particles_per_rank"]
end = max(parts) * len(parts) / sum(parts)
total = lambda k: sum(float(f[k]) for f in frames)
print(",".join([scene, scale, solver, str(dist["ranks"]), str(run["threads"]), above, rep, str(run["particles"]),
                str(len(frames)), str(int(total("steps"))), str(int(total("outer_iters"))),
                str(int(total("linear_iters"))), f"{total('wall_s'):.6f}", str(dist["recuts"]),
                f"{dist['worst_imbalance']:.4f}", f"{end:.4f}", str(sum(dist["particles_sent_per_rank"])),
                str(int(run["machine_load"]["machine_busy"])), version]))
PY
    if [ -t 2 ]; then echo "repeat $rep: --rebalance-above $above done" >&2; fi
  done
done
python3 "$root/scripts/rebalance_study.py" "$csv" >"$out/rebalance.md"
echo "wrote $csv and $out/rebalance.md" >&2
