#!/usr/bin/env bash
# Every scene of the suite runs one frame at a coarse scale (~4k particles)
# with HOT: exit 0 (no NaN, no particle leaving the domain) and every step
# converged to the CN tolerance.
set -u
bin="$1"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fails=0
checks=0
# scene and the --scale giving about 4k particles (Table 2 counts / 4000)^(1/3)
for entry in "drop 1" "bar3 4.3" "stretched-box 3.6" "twist 3.9" "boxes 5.9" "donut 4" "armacat-soft 4.7" \
             "armacat-stiff 4.7" "chain 4.3" "boards 3.6" "wheel 5.2" "faceless 3" "sauce 4.3"; do
  set -- $entry
  scene=$1
  scale=$2
  checks=$((checks + 1))
  if ! "$bin" run --scene "$scene" --solver hot --scale "$scale" --frames 1 --quiet --out "$tmp/$scene" \
       >"$tmp/$scene.log" 2>&1; then
    echo "FAIL: $scene at scale $scale: $(tail -1 "$tmp/$scene.log")"
    fails=$((fails + 1))
    continue
  fi
  bad=$(awk -F, 'NR > 1 && $14 != "converged" {n++} END {print n + 0}' "$tmp/$scene/steps.csv")
  steps=$(($(wc -l <"$tmp/$scene/steps.csv") - 1))
  checks=$((checks + 1))
  if [ "$bad" -ne 0 ] || [ "$steps" -lt 1 ]; then
    echo "FAIL: $scene: $bad of $steps steps not converged"
    fails=$((fails + 1))
  else
    echo "ok: $scene ($steps steps, $(sed -n 2p "$tmp/$scene/steps.csv" | cut -d, -f7) particles)"
  fi
done
echo "$((checks - fails)) passed, $fails failed"
[ "$fails" -eq 0 ]
