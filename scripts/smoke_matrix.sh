#!/usr/bin/env bash
# Smoke matrix: every scene of the suite x every chosen solver at a coarse
# scale (about 4k particles at the last frame), checking that each run exits 0
# (no NaN, no particle leaving the domain) and that every step converged to
# the CN tolerance. CTest runs it with --solvers hot (tests/test_scenes_run.sh); run
# it with --solvers all to check that every preset runs every scene.
#
# usage: scripts/smoke_matrix.sh [--bin PATH] [--solvers "a b"|all]
#            [--frames F] [--out DIR] [--threads T] [--asset-dir DIR]
#
# --asset-dir DIR (the folder with the original meshes, e.g.
# ../shared/data/meshes) adds the mesh variants armacat-soft-mesh,
# armacat-stiff-mesh, wheel-mesh and sauce-mesh.
#
# Frames: one per scene, except where the action starts later: Boards runs 12
# (the sand reaches the top board after about 0.2 s) and Sauce 24 at a finer
# scale (it starts empty; its source emits about 140 particles per frame
# there). --frames F runs F frames of every scene instead.
#
# Output: one line per run on stdout, OUT/summary.csv (scene, solver, scale,
# frames, exit code, steps, steps not converged, outer and linear iterations,
# particles, wall seconds, inner iterations) and exit 1 if any run failed.
set -u
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin="$root/build/mpmbench"
solvers=hot
frames=""
out=""
threads=${OMP_NUM_THREADS:-2}
asset_dir=""
die() { echo "smoke_matrix: $*" >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --bin) bin=${2:?--bin needs a path}; shift 2 ;;
    --solvers) solvers=${2:?--solvers needs a list}; shift 2 ;;
    --frames) frames=${2:?--frames needs a number}; shift 2 ;;
    --out) out=${2:?--out needs a directory}; shift 2 ;;
    --threads) threads=${2:?--threads needs a number}; shift 2 ;;
    --asset-dir) asset_dir=${2:?--asset-dir needs a directory}; shift 2 ;;
    *) die "unknown argument '$1'" ;;
  esac
done
[ -x "$bin" ] || die "no executable at $bin (build first: bash scripts/setup.sh)"
# presets: the listing's first block (outer methods and inverse approximations follow a blank line)
if [ "$solvers" = all ]; then solvers=$("$bin" list solvers | awk 'NF == 0 {exit} {print $1}'); fi
if [ -z "$out" ]; then
  out=$(mktemp -d)
  trap 'rm -rf "$out"' EXIT
fi
mkdir -p "$out"
summary="$out/summary.csv"
echo "scene,solver,scale,frames,exit,steps,not_converged,outer_iters,linear_iters,particles,wall_s,inner_iters" >"$summary"

fails=0
runs=0
# scene, the --scale giving about 4k particles ((Table 2 count / 4000)^(1/3)), frames
entries=("drop 1 1" "bar3 4.3 1" "stretched-box 3.6 1" "twist 3.9 1" "boxes 5.9 1" "donut 4 1"
         "armacat-soft 4.7 1" "armacat-stiff 4.7 1" "chain 4.3 1" "boards 3.6 12" "wheel 5.2 1" "faceless 3 1"
         "sauce 2.5 24")
asset_args=()
if [ -n "$asset_dir" ]; then
  [ -d "$asset_dir" ] || die "--asset-dir $asset_dir: not a directory"
  entries+=("armacat-soft-mesh 4.7 1" "armacat-stiff-mesh 4.7 1" "wheel-mesh 5.2 1" "sauce-mesh 2.5 24")
  asset_args=(--asset-dir "$asset_dir")
fi
for entry in "${entries[@]}"; do
  set -- $entry
  scene=$1
  scale=$2
  scene_frames=${frames:-$3}
  for solver in $solvers; do
    runs=$((runs + 1))
    dir="$out/$scene/$solver"
    mkdir -p "$out/$scene"
    start=$(date +%s.%N)
    "$bin" run --scene "$scene" --solver "$solver" --scale "$scale" --frames "$scene_frames" --threads "$threads" \
      "${asset_args[@]}" \
      --quiet --out "$dir" >"$dir.log" 2>&1
    code=$?
    wall=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN {printf "%.2f", b - a}')
    stats="0,0,0,0,0"
    inner=0
    if [ -s "$dir/steps.csv" ]; then
      stats=$(awk -F, 'NR > 1 {n++; if ($14 != "converged") bad++; o += $10; l += $11; p = $7}
                       END {printf "%d,%d,%d,%d,%d", n, bad, o, l, p}' "$dir/steps.csv")
      inner=$(awk -F, 'NR == 1 {for (k = 1; k <= NF; ++k) if ($k == "inner_iters") c = k} NR > 1 && c {i += $c}
                       END {printf "%d", i}' "$dir/steps.csv")
    fi
    echo "$scene,$solver,$scale,$scene_frames,$code,$stats,$wall,$inner" >>"$summary"
    IFS=, read -r steps bad outer linear particles <<<"$stats"
    if [ "$code" -ne 0 ]; then
      echo "FAIL: $scene $solver (scale $scale): exit $code: $(tail -1 "$dir.log")"
      fails=$((fails + 1))
    elif [ "$bad" -ne 0 ] || [ "$steps" -lt 1 ]; then
      echo "FAIL: $scene $solver: $bad of $steps steps not converged"
      fails=$((fails + 1))
    else
      echo "ok: $scene $solver ($particles particles, $steps steps, $outer outer / $linear linear / $inner inner iterations, ${wall} s)"
    fi
  done
done
echo "$((runs - fails)) of $runs runs passed"
[ "$fails" -eq 0 ]
