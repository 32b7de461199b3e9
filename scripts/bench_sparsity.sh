#!/usr/bin/env bash
# HOT Fig. 8: nonzero blocks per row on each multigrid level, for the node-
# embedding Galerkin hierarchy with the linear kernel (hot), the same with the
# quadratic kernel (hot-quadratic) and the particle-rediscretised geometric
# multigrid (lbfgs-gmg), on ArmaCat with five levels as in the figure (the
# solvers use three). One frame each; the table comes from mg_levels.csv,
# the hierarchy of each run's last step.
#
# usage: scripts/bench_sparsity.sh   (env: MPMBENCH, SCENE, SCALE, LEVELS, OUT)
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${MPMBENCH:-build-native/mpmbench}"
scene="${SCENE:-armacat-stiff}"
scale="${SCALE:-2}"
levels="${LEVELS:-5}"
out="${OUT:-results/fig8}"
mkdir -p "$out"
for s in hot hot-quadratic lbfgs-gmg; do
  "$bin" run --scene "$scene" --scale "$scale" --frames 1 --solver "$s" --solver-opt levels="$levels" \
    --solver-opt min_coarse_nodes=1 --quiet --out "$out/$scene-$s"
done
python3 - "$out" "$scene" "$levels" <<'PY' | tee "$out/summary.md"
import csv, sys
out, scene, levels = sys.argv[1], sys.argv[2], int(sys.argv[3])
names = [("hot", "Galerkin, linear embedding (HOT)"), ("hot-quadratic", "Galerkin, quadratic embedding"),
         ("lbfgs-gmg", "rediscretised geometric MG")]
cols = {}
for s, _ in names:
    with open(f"{out}/{scene}-{s}/mg_levels.csv", newline="") as f:
        cols[s] = list(csv.DictReader(f))
print(f"Nonzero 3x3 blocks per row (mean / max) per level, {scene}, last step of frame 0 "
      f"(HOT Fig. 8 shows scalar nonzeros per row, 3x these):\n")
print("| level | " + " | ".join(label for _, label in names) + " |")
print("|---|" + "---|" * len(names))
for l in range(levels):
    cells = []
    for s, _ in names:
        rows = cols[s]
        cells.append(f"{float(rows[l]['blocks_per_row_avg']):.1f} / {rows[l]['blocks_per_row_max']} "
                     f"({int(rows[l]['nodes']):,} nodes)" if l < len(rows) else "-")
    print(f"| {l} | " + " | ".join(cells) + " |")
PY
