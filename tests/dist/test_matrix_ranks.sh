#!/usr/bin/env bash
# needs: MPM_WITH_PETSC
# A matrix file's `ranks` key (docs/matrix.md, docs/distributed.md): a cell
# with ranks R > 1 runs under `mpirun -np R` (cmd.txt says so), and its
# steps are the one-process cell's (pn-pcg: the same outer and linear
# iterations, docs/distributed.md); cells.csv gets a ranks column and the
# cell's run.json the split. `run --ranks R` refuses any other count of
# ranks (one process, or mpirun with another count: exit 2 on every rank,
# no hang). A cell over ranks with a reference run is refused when the
# matrix is read. A cell over ranks killed at its timeout leaves no rank
# behind and is not called a busy machine (its ranks' CPU time died with
# mpirun, so the others' time is unknown).
. "$(dirname "$0")/../common/shell_harness.sh"
command -v mpirun >/dev/null || skip "mpirun not found (Debian package openmpi-bin)"
cat >"$tmp/m.json" <<'JSON'
{"name": "ranks", "defaults": {"scene": "bar3", "scale": 4, "frames": 2, "threads": 1, "solver": "pn-pcg"},
 "axes": {"ranks": [1, 2, 3]}}
JSON
"$bin" matrix run "$tmp/m.json" --out "$tmp/m" >"$tmp/out" 2>&1
rc=$?
check "matrix with a ranks axis: exit 0 ($(tail -2 "$tmp/out"))" test $rc -eq 0
python3 - "$tmp/m" >"$tmp/cmp" 2>&1 <<'PY'
import csv, json, sys
d = sys.argv[1]
rows = {int(r["ranks"]): r for r in csv.DictReader(open(f"{d}/cells.csv"))}
assert sorted(rows) == [1, 2, 3], sorted(rows)
for r, row in rows.items():
    assert row["status"] == "ok", row
    for k in ("steps", "outer_iters", "linear_iters", "particles"):
        assert row[k] == rows[1][k], (r, k, row[k], rows[1][k])
    cmd = open(f"{d}/cells/{row['id']}/cmd.txt").read()
    assert cmd.startswith(f"mpirun -np {r} mpmbench run") == (r > 1), cmd
    run = json.load(open(f"{d}/cells/{row['id']}/run.json"))
    assert ("distributed" in run) == (r > 1), r
    if r > 1:
        assert run["distributed"]["ranks"] == r and len(run["distributed"]["particles_per_rank"]) == r, run["distributed"]
print("ok")
PY
check "cells over 1, 2 and 3 ranks: the same steps and iterations ($(tail -1 "$tmp/cmp"))" grep -qx ok "$tmp/cmp"

R=(run --scene bar3 --scale 4 --frames 1 --threads 1 --quiet --solver pn-pcg)
"$bin" "${R[@]}" --ranks 2 --out "$tmp/one" >"$tmp/out" 2>&1
rc=$?
check "run --ranks 2 as one process: exit 2 ($rc: $(head -1 "$tmp/out"))" test $rc -eq 2 -a "$(grep -c '^mpmbench: error: --ranks 2: this run is one process' "$tmp/out")" -eq 1
mpirun_ranks -np 2 "$bin" "${R[@]}" --ranks 3 --out "$tmp/two" >"$tmp/out" 2>&1
rc=$?
check "run --ranks 3 on 2 ranks: exit 2 on every rank ($rc: $(head -1 "$tmp/out"))" test $rc -eq 2 -a "$(grep -c '^mpmbench: error: --ranks 3: this run is on 2 MPI ranks' "$tmp/out")" -eq 2

cat >"$tmp/ref.json" <<'JSON'
{"name": "ranksref", "defaults": {"scene": "bar3", "scale": 4, "frames": 2, "solver": "pn-pcg", "ranks": 2},
 "reference": {"solver": "pn-pcg"}}
JSON
"$bin" matrix run "$tmp/ref.json" --out "$tmp/ref" >"$tmp/out" 2>&1
rc=$?
check "ranks with a reference run: exit 2, one line ($rc: $(head -1 "$tmp/out"))" test $rc -eq 2 -a "$(grep -c 'ranks 2: not with a reference run' "$tmp/out")" -eq 1 -a "$(wc -l <"$tmp/out")" -eq 1

# a cell far longer than its 2 s limit on any machine (scale 2, 40 frames)
cat >"$tmp/t.json" <<'JSON'
{"name": "rankstimeout", "cell_timeout_s": 2, "defaults": {"scene": "bar3", "scale": 2, "frames": 40, "threads": 1,
 "solver": "pn-pcg", "ranks": 2}}
JSON
"$bin" matrix run "$tmp/t.json" --out "$tmp/t" >"$tmp/out" 2>&1
left=1
for _ in $(seq 50); do
  pgrep -f "$tmp/t/cells" >/dev/null || { left=0; break; }
  sleep 0.2
done
check "a timed-out cell over ranks leaves no process behind" test $left -eq 0
check "its status is timeout and its machine not busy ($(cut -d, -f1-3 "$tmp/t/cells.csv" | tail -1))" python3 -c "
import csv, sys
r = list(csv.DictReader(open('$tmp/t/cells.csv')))
assert len(r) == 1 and r[0]['status'] == 'timeout' and r[0]['machine_busy'] == '0' and r[0]['others_cpu_s'] == '', r"
finish
