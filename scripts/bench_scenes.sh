#!/usr/bin/env bash
# Seconds per frame of pn-pcg and hot on every scene at the 2-core benchmark
# scale (~50k particles at the start), FRAMES frames each, THREADS threads.
# Writes results/scenes-bench/<scene>/<solver>/ and a summary table.
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${MPMBENCH:-build-native/mpmbench}"
frames="${FRAMES:-2}"
threads="${THREADS:-2}"
solvers="${SOLVERS:-pn-pcg hot}"
out="${OUT:-results/scenes-bench}"
while read -r scene scale; do
  for s in $solvers; do
    dir="$out/$scene/$s"
    if [ -f "$dir/frames.csv" ] && [ "$(($(wc -l <"$dir/frames.csv") - 1))" -ge "$frames" ]; then continue; fi
    timeout "${TIMEOUT:-900}" "$bin" run --scene "$scene" --solver "$s" --scale "$scale" --frames "$frames" \
      --threads "$threads" --quiet --out "$dir" || echo "warning: $scene/$s did not finish" >&2
  done
done <<'LIST'
twist 1.66
boxes 2.52
donut 1.7
armacat-soft 2
armacat-stiff 2
chain 1.83
boards 1.55
wheel 2.22
faceless 1.3
sauce 1.5
bar3 1.86
stretched-box 1.55
drop 1
LIST
python3 scripts/summarize.py --baseline pn-pcg "$out" | tee "$out/summary.md"
