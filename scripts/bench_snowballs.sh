#!/usr/bin/env bash
# Gast et al. 2015 Fig. 18 at reduced scale: on the three snowball scenes
# (Fig. 14 drop, Fig. 17 wall, Fig. 16 collide), each solver's minimum and
# average time step, steps, seconds per frame and outer/linear iterations
# over the whole scene, at the 2-core benchmark scale (~35k particles).
# Writes results/snowball-bench/<scene>/<solver>/ and summary.csv.
#
#   SOLVERS="hot pn-pcg"   solvers (presets) to run (e.g. add gast15,
#                          semi-implicit once they exist)
#   THREADS=2  FRAMES=N    (N overrides every scene's frame count)
#   SET="cfl=0.6"          extra --set overrides for every run (space-separated
#                          key=value; e.g. SET="max_dt=1e-4" for a
#                          fixed-step semi-implicit comparison)
#   MPMBENCH=path, OUT=dir
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${MPMBENCH:-build-native/mpmbench}"
threads="${THREADS:-2}"
solvers="${SOLVERS:-hot pn-pcg}"
out="${OUT:-results/snowball-bench}"
sets=()
for kv in ${SET:-}; do sets+=(--set "$kv"); done
mkdir -p "$out"
summary="$out/summary.csv"
echo "scene,solver,scale,particles,frames,steps,min_dt,avg_dt,s_per_frame,outer_iters,linear_iters,not_converged" >"$summary"
# scene, --scale (about 35k particles)
while read -r scene scale; do
  for s in $solvers; do
    dir="$out/$scene/$s"
    frame_args=()
    [ -n "${FRAMES:-}" ] && frame_args=(--frames "$FRAMES")
    timeout "${TIMEOUT:-3600}" "$bin" run --scene "$scene" --solver "$s" --scale "$scale" "${frame_args[@]}" \
      "${sets[@]}" --threads "$threads" --quiet --out "$dir" || echo "warning: $scene/$s did not finish" >&2
    [ -s "$dir/steps.csv" ] || continue
    awk -F, -v scene="$scene" -v solver="$s" -v scale="$scale" -v fr="$dir/frames.csv" '
      NR > 1 { n++; dt = $6; sum += dt; if (min == "" || dt < min) min = dt; o += $10; l += $11; p = $7
               if ($14 != "converged") bad++ }
      END {
        frames = 0; wall = 0
        while ((getline line < fr) > 0) { if (++k == 1) continue; split(line, f, ","); frames++; wall += f[7] }
        printf "%s,%s,%s,%d,%d,%d,%.3e,%.3e,%.4f,%d,%d,%d\n", scene, solver, scale, p, frames, n, min, sum / n,
               frames ? wall / frames : 0, o, l, bad
      }' "$dir/steps.csv" >>"$summary"
  done
done <<'LIST'
snowball-drop 2
snowball-wall 2
snowball-collide 2.5
LIST
column -s, -t "$summary"
