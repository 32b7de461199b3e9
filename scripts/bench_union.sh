#!/usr/bin/env bash
# Scene loading with a large CSG union (issue 12): a union of N random
# 0.02 m boxes in a 1 m domain (dx 0.02, ppc 8), loaded and sampled by
# `mpmbench render --frame 0`. Prints N, particles and wall seconds.
#   scripts/bench_union.sh [N=20000] [THREADS=2]
# Before the union's box tree (core/scene/box_tree.h) N = 20000 took > 200 s.
set -euo pipefail
cd "$(dirname "$0")/.."
n=${1:-20000} threads=${2:-2}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 - "$n" "$tmp/union.json" <<'PY'
import json, random, sys
n, out = int(sys.argv[1]), sys.argv[2]
random.seed(5)
boxes = []
for _ in range(n):
    x, y, z = (random.uniform(0.1, 0.88) for _ in range(3))
    boxes.append({"type": "box", "min": [x, y, z], "max": [x + 0.02, y + 0.02, z + 0.02]})
json.dump({"name": "union", "dx": 0.02, "fps": 24, "frames": 1, "gravity": [0, -9.8, 0],
           "domain": {"min": [0, 0, 0], "max": [1, 1, 1]},
           "materials": {"a": {"E": 1e5, "nu": 0.3, "density": 1000}},
           "objects": [{"material": "a", "ppc": 8, "shape": {"type": "union", "shapes": boxes}}]}, open(out, "w"))
PY
t0=$(date +%s.%N)
out=$(build/mpmbench render --scene "$tmp/union.json" --frame 0 --threads "$threads" --out "$tmp/u.png")
t1=$(date +%s.%N)
echo "union of $n boxes: $(echo "$out" | sed -n 's/.*, \([0-9]*\) particles).*/\1/p') particles, $(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.2f", b - a}') s ($threads threads)"
