#!/usr/bin/env bash
# Counts the halo volumes of the benchmark scenes split over 1, 2, 4, ...,
# 512 ranks at the paper's resolution (scale 1) with `mpmbench decompose`
# (up to the count at which a scene has more ranks than node blocks)
# into results/distributed/census.csv, then writes census.md
# (scripts/halo_model.py). Counting, not timing: the numbers do not depend
# on the machine's load.
#
#   scripts/distributed_census.sh [BUILD_DIR] [--asset-dir DIR]
#
# The mesh scenes (armacat-*, faceless, wheel) need the original meshes
# (--asset-dir; the stand-in meshes of the tests change the counts); sauce
# and boards start empty and fill from sources, so they are counted at a
# frame where they hold particles, from a checkpoint of a run at scale 1.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
shift || true
assets=()
[ $# -ge 2 ] && [ "$1" = --asset-dir ] && assets=(--asset-dir "$2")
out=$root/results/distributed
mkdir -p "$out"
csv=$out/census.csv
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
first=1
for scene in bar3 twist donut armacat-soft armacat-stiff faceless chain wheel boxes; do
  for ranks in 1 2 4 8 16 32 64 128 256 512; do
    # a scene with fewer node blocks than ranks ends its series (decompose refuses it)
    "$build/mpmbench" decompose --scene "$scene" --scale 1 --ranks $ranks "${assets[@]}" --out "$tmp/$scene.csv" \
      2>"$tmp/err" || { grep -q "more ranks than blocks" "$tmp/err" && break; cat "$tmp/err" >&2; exit 1; }
    if [ $first = 1 ]; then cat "$tmp/$scene.csv"; first=0; else tail -n +2 "$tmp/$scene.csv"; fi
  done
  echo "counted $scene" >&2
done >"$csv"
{
  echo "counted by: $("$build/mpmbench" --version)"
  echo "date: $(date -u +%Y-%m-%d)"
} >"$out/provenance.txt"
python3 "$root/scripts/halo_model.py" "$csv" --study "$root/results/petsc-baselines" \
  --provenance "$out/provenance.txt" >"$out/census.md"
echo "wrote $csv and $out/census.md" >&2
