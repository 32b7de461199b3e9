#!/usr/bin/env bash
# Times two builds of mpmbench on the same run, alternately, so that drift
# of the machine hits both alike:
#   scripts/compare_builds.sh OLD_BINARY NEW_BINARY REPEATS OUT_DIR -- RUN_ARGS...
# e.g. scripts/compare_builds.sh old/build/mpmbench build/mpmbench 3 out/cmp -- \
#        --scene bar3 --scale 1 --frames 2 --solver hot --threads 2 --set cfl_rule=reference
# Each run writes OUT_DIR/{old,new}-R/; one line per run on stdout: seconds
# per frame (frames.csv), the summed phases (steps.csv), outer iterations
# and peak resident memory (GNU time). Run it alone on the machine.
set -euo pipefail
if [ $# -lt 5 ] || [ "$5" != "--" ]; then
  echo "usage: scripts/compare_builds.sh OLD_BINARY NEW_BINARY REPEATS OUT_DIR -- RUN_ARGS..." >&2
  exit 2
fi
old=$1 new=$2 reps=$3 out=$4
shift 5
[[ "$reps" =~ ^[1-9][0-9]*$ ]] || { echo "compare_builds.sh: REPEATS '$reps': expected a positive integer" >&2; exit 2; }
for b in "$old" "$new"; do [ -x "$b" ] || { echo "compare_builds.sh: '$b' is not an executable" >&2; exit 2; }; done
[ -x /usr/bin/time ] || { echo "compare_builds.sh: needs GNU time (/usr/bin/time, Debian package time)" >&2; exit 2; }
mkdir -p "$out"
echo "build,repeat,frame_s,wall_s,p2g_s,assemble_s,setup_s,solve_s,linesearch_s,g2p_s,outer_iters,particles,peak_rss_mb"
for r in $(seq "$reps"); do
  for which in old new; do
    bin=$old
    [ "$which" = new ] && bin=$new
    dir="$out/$which-$r"
    rm -rf "$dir"
    /usr/bin/time -f "%M" -o "$out/$which-$r.rss" "$bin" run "$@" --quiet --out "$dir" >/dev/null
    python3 - "$dir" "$which" "$r" "$(cat "$out/$which-$r.rss")" <<'PY'
import csv, sys
d, which, rep, rss_kb = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
steps = list(csv.DictReader(open(f"{d}/steps.csv")))
frames = list(csv.DictReader(open(f"{d}/frames.csv")))
tot = lambda k: sum(float(s[k] or 0) for s in steps)
phases = ",".join(f"{tot(k):.3f}" for k in ("wall_s", "p2g_s", "assemble_s", "setup_s", "solve_s", "linesearch_s", "g2p_s"))
frame_s = sum(float(f["wall_s"]) for f in frames) / len(frames)
print(f"{which},{rep},{frame_s:.3f},{phases},{int(tot('outer_iters'))},{steps[0]['particles']},{rss_kb / 1024:.1f}")
PY
  done
done
