#!/usr/bin/env bash
# Seconds per frame of pn-pcg and hot on every scene at the 2-core benchmark
# scale (~50k particles at the start), THREADS threads. Each scene is timed
# over a window of frames where its solve has work: a pusher that needs a few
# frames to reach its target (Boxes, Chain, Wheel, Drop), sand that reaches
# the boards after 0.2 s, sauce that starts empty, are simulated up to the
# window (with the same solver) and timed inside it (summarize.py
# --from-frame). Writes results/scenes-bench/<scene>/<solver>/ and a summary
# table. FRAMES=N overrides every scene's frame count (and drops windows).
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${MPMBENCH:-build-native/mpmbench}"
threads="${THREADS:-2}"
solvers="${SOLVERS:-pn-pcg hot}"
out="${OUT:-results/scenes-bench}"
windows=()
# scene, --scale, frames simulated, first timed frame (0-based)
while read -r scene scale frames from; do
  if [ -n "${FRAMES:-}" ]; then frames=$FRAMES; from=0; fi
  [ "$from" -gt 0 ] && windows+=(--from-frame "$scene=$from")
  for s in $solvers; do
    dir="$out/$scene/$s"
    if [ -f "$dir/frames.csv" ] && [ "$(($(wc -l <"$dir/frames.csv") - 1))" -ge "$frames" ]; then continue; fi
    timeout "${TIMEOUT:-1800}" "$bin" run --scene "$scene" --solver "$s" --scale "$scale" --frames "$frames" \
      --threads "$threads" --quiet --out "$dir" || echo "warning: $scene/$s did not finish" >&2
  done
done <<'LIST'
twist 1.66 4 0
boxes 2.52 9 4
donut 1.7 3 0
armacat-soft 2 3 0
armacat-stiff 2 3 0
chain 1.83 9 5
boards 1.55 8 5
wheel 2.22 5 2
faceless 1.3 3 0
sauce 1.5 30 24
bar3 1.86 5 0
stretched-box 1.55 1 0
drop 1 8 4
LIST
python3 scripts/summarize.py --baseline pn-pcg "${windows[@]}" "$out" | tee "$out/summary.md"
