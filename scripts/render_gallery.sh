#!/usr/bin/env bash
# Renders the gallery of initial states (results/scenes/): every paper scene at its benchmark scale
# (about 50k-150k particles on 2 cores), initial state, iso view; the two
# particle-source scenes also at a later frame (coarser, so it simulates in
# minutes). Usage: scripts/render_gallery.sh [mpmbench binary]
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${1:-build/mpmbench}"
out=results/scenes
mkdir -p "$out"
while read -r scene scale; do
  "$bin" render --scene "$scene" --scale "$scale" --view iso --out "$out/$scene.png"
done <<'LIST'
twist 1.3
boxes 2
donut 1.35
armacat-soft 1.6
armacat-stiff 1.6
chain 1.45
boards 1.25
wheel 1.75
faceless 1
sauce 1.5
bar3 1.86
stretched-box 1.25
drop 1
LIST
"$bin" render --scene boards --scale 2.5 --frame 48 --solver hot --view iso --out "$out/boards-frame48.png"
"$bin" render --scene sauce --scale 3 --frame 72 --solver hot --view iso --out "$out/sauce-frame72.png"
