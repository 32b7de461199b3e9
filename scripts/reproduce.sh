#!/usr/bin/env bash
# Regenerates a committed study and the numbers the documentation quotes
# from it, with one command:
#
#   scripts/reproduce.sh NAME [--dry-run]
#
# NAME is a folder of results/ made by `matrix run` (or the path of one).
# The script says how long the committed run took (the sum of its cells'
# elapsed time, on the machine its status line names), then runs the
# study's matrix file with the options its invocations recorded
# (provenance.json "options": the threads and other options of the last;
# when every invocation ran a part (--only), the scenes and solvers of the
# committed cells, so a study made scene by scene is made again whole and
# nothing more; the studies made differently, listed in results/README.md,
# with theirs) into NAME.new, writes its report, replaces results/NAME with it, and
# refills the quoted numbers (scripts/fill_numbers.py) and the study's
# status. The new study is current for this build; the old one stays in git.
#
# Environment: MPMBENCH, the program (default build-native/mpmbench, a build
# for this machine: cmake -S . -B build-native -DMPM_NATIVE=ON). Run it on an
# otherwise idle machine: every cell records the machine's load, and cells
# run beside other work are flagged busy and cannot be quoted.
set -euo pipefail
set -f # the --only globs go to mpmbench as they are
usage() { echo "usage: scripts/reproduce.sh NAME [--dry-run]   (NAME: a folder of results/ with a matrix.json, or its path)" >&2; exit 2; }
[ $# -ge 1 ] || usage
dir=results/$1
case $1 in */*) dir=$(cd "$1" 2>/dev/null && pwd) || { echo "reproduce.sh: $1: no such folder" >&2; exit 2; } ;; esac
name=$(basename "$dir")
dry=${2:-}
[ -z "$dry" ] || [ "$dry" = --dry-run ] || usage
cd "$(dirname "$0")/.."
bin=${MPMBENCH:-build-native/mpmbench}
[ -f "$dir/matrix.json" ] || { echo "reproduce.sh: $dir has no matrix.json: not a matrix study (see its README)" >&2; exit 2; }
[ -x "$bin" ] || { echo "reproduce.sh: $bin is not built (cmake -S . -B build-native -DMPM_NATIVE=ON && cmake --build build-native, or set MPMBENCH)" >&2; exit 2; }

# the matrix file, the committed cells' scenes and solvers, and the other options of the last invocation
mapfile -t spec < <(python3 - "$dir" <<'PY'
import csv, json, os, sys
d = sys.argv[1]
m = json.load(open(os.path.join(d, "matrix.json")))
f = m["file"] if os.path.isfile(m["file"]) else os.path.join("experiments/matrices", os.path.basename(m["file"]))
inv = json.load(open(os.path.join(d, "provenance.json")))["invocations"]
opts = [i["options"] for i in inv if "options" in i]
o = opts[-1] if opts else None
args = []
if opts and all(x["only"] for x in opts):  # else one invocation ran every cell
    # a scene with a cell of every solver of the matrix as scene/*, else its scene/solver pairs
    every = (m.get("matrix") or {}).get("axes", {}).get("solver") or []
    pairs = {}
    for r in csv.DictReader(open(os.path.join(d, "cells.csv"))):
        pairs.setdefault(r["scene"], {})[r["solver"]] = None
    for scene, solvers in pairs.items():
        whole = bool(every) and set(every) <= set(solvers)
        args += [a for so in (["*"] if whole else solvers) for a in ("--only", f"{scene}/{so}")]
if o:
    if o["threads"]:
        args += ["--threads", str(o["threads"])]
    if o["asset_dir"]:
        args += ["--asset-dir", o["asset_dir"]]
    if o["check"]:
        args += ["--check"]
print("\n".join([f] + args))  # one word a line: the globs reach mpmbench unquoted and unexpanded
PY
)
file=${spec[0]}
args=("${spec[@]:1}")
launcher=()
case $name in # studies made differently (results/README.md), recorded before provenance.json kept options
  stress) [ ${#args[@]} -gt 0 ] || args=(--check) ;;
  scenes-mpi2x1)
    launcher=(mpirun --allow-run-as-root -np 2 --bind-to core)
    [ ${#args[@]} -gt 0 ] || args=(--threads 1 --only 'twist/*' --only 'armacat-*/*' --only 'chain/*' --only 'faceless/*'
      --only 'sauce/*' --only 'bar3/*' --only 'stretched-box/*' --only 'drop/*') ;;
  foundation) [ -z "$dry" ] && { MPMBENCH=$bin scripts/bench_foundation.sh; exec python3 scripts/fill_numbers.py; } ;;
esac

python3 - "$dir" <<'PY'
import csv, json, os, sys
d = sys.argv[1]
rows = list(csv.DictReader(open(os.path.join(d, "cells.csv"))))
secs = sum(float(r.get("elapsed_s") or 0) for r in rows)
inv = json.load(open(os.path.join(d, "provenance.json")))["invocations"]
cpu = inv[-1].get("cpu_model", "?") if inv else "?"
print(f"reproduce.sh: {os.path.basename(d)}: {len(rows)} cells; the committed run's cells took {secs / 60:.0f} min "
      f"together on {cpu} (the ranks and jobs of its invocation run them side by side)")
PY
echo "reproduce.sh: $(printf '%q ' "${launcher[@]}" "$bin" matrix run "$file" "${args[@]}" --out "$dir.new")"
[ -z "$dry" ] || exit 0
load=$(cut -d' ' -f1 /proc/loadavg)
echo "reproduce.sh: load average now $load on $(nproc) cores (run alone on the machine)"
rm -rf "$dir.new"
start=$(date +%s)
"${launcher[@]}" "$bin" matrix run "$file" "${args[@]}" --out "$dir.new"
# the study's bounds (a solver too slow to time in the matrix, run once from the same checkpoints and
# stopped by its --max-run-seconds: scripts/paper_scale_table.py), run again the same way
python3 scripts/paper_scale_table.py --rerun-bounds "$dir" "$dir.new" "$bin"
"$bin" matrix report "$dir.new"
rm -rf "$dir"
mv "$dir.new" "$dir"
case $name in # the paper-scale table is one page over its two parts (one machine each): remade with either
  paper-scale|paper-scale-xeon)
    if [ -d results/paper-scale ] && [ -d results/paper-scale-xeon ] &&
      ! python3 scripts/paper_scale_table.py --out results/paper-scale/table.md results/paper-scale results/paper-scale-xeon; then
      echo "reproduce.sh: results/paper-scale/table.md kept: its two parts cannot form one table (above); reproduce the other part with this build too" >&2
    fi ;;
esac
python3 scripts/fill_numbers.py
MPM_BINARY=$bin python3 scripts/study_status.py --binary "$bin" "$dir"
echo "reproduce.sh: $name regenerated in $(( ($(date +%s) - start) / 60 )) min; review and commit results/$name and the refilled pages"
