#!/usr/bin/env bash
# Does one scene split over R ranks follow the one-process trajectory? bar3
# (scale 2), twist (scale 4), boards (scale 4: a source pours sand on
# boards) and snowball-drop (scale 4, past its impact: snow plasticity,
# grid-density volumes, PIC/FLIP, backward-Euler positions), each with
# projected Newton's matrix-free PCG (pn-pcg-mf) and HOT (hot-petsc), on 1,
# 2, 3 and 4 ranks x 1 thread (oversubscribed on 2 cores: nothing here is
# timed). Every run writes --vtk; scripts/rank_agreement.py compares each
# frame's particles by id with the one-rank run's: the largest position
# difference (metres and cells), the whole scene's mass and momentum, and
# the iteration counts.
# Writes results/distributed/agreement.csv (one row per run) and
# agreement.md.
#
#   scripts/rank_agreement.sh [BUILD_DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$root/build}
out=$root/results/distributed
mkdir -p "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
version=$("$build/mpmbench" --version | sed 's/.*git \([0-9a-f]\{7\}\)[0-9a-f]*\(, modified\)\{0,1\}.*/\1\2/; s/, modified/+modified/')
runs=()
for case in bar3:2:4 twist:4:4 boards:4:24 snowball-drop:4:16; do
  IFS=: read -r scene scale frames <<<"$case"
  for solver in pn-pcg-mf hot-petsc; do
    for ranks in 1 2 3 4; do
      dir=$tmp/$scene-$solver-$ranks
      args=(run --scene "$scene" --scale "$scale" --frames "$frames" --solver "$solver" --threads 1 --quiet
            --out "$dir" --vtk "$dir/vtk")
      if [ "$ranks" = 1 ]; then "$build/mpmbench" "${args[@]}" 2>/dev/null
      else mpirun --oversubscribe --allow-run-as-root --bind-to none -np "$ranks" "$build/mpmbench" "${args[@]}" --ranks "$ranks" 2>/dev/null; fi
      runs+=("$scene,$scale,$solver,$ranks,$dir")
      if [ -t 2 ]; then echo "$scene scale $scale $solver on $ranks ranks done" >&2; fi
    done
  done
done
/usr/bin/python3 "$root/scripts/rank_agreement.py" "$out/agreement.csv" "$version" "${runs[@]}" >"$out/agreement.md"
echo "wrote $out/agreement.csv and $out/agreement.md" >&2
