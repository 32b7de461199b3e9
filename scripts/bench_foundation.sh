#!/usr/bin/env bash
# Issue-2 figures in one run: kernel throughput (bench all) and the per-frame
# wall time of pn-pcg and pn-pcg-mf on bar3 (middle E = 1e9) at ~50k
# particles, 5 frames, 2 threads. Writes results/foundation/.
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${MPMBENCH:-build-native/mpmbench}"
scale="${SCALE:-1.86}"
threads="${THREADS:-2}"
out=results/foundation
mkdir -p "$out"
"$bin" bench all --scene bar3 --scale "$scale" --set materials.middle.E=1e9 --threads "$threads" | tee "$out/bench.txt"
for s in pn-pcg pn-pcg-mf; do
  "$bin" run --scene bar3 --solver "$s" --scale "$scale" --frames 5 --set materials.middle.E=1e9 \
    --threads "$threads" --quiet --out "$out/bar3-E1e9-$s"
done
python3 scripts/summarize.py --baseline pn-pcg "$out"/bar3-E1e9-* | tee "$out/summary.md"
