#!/usr/bin/env bash
# needs: MPM_WITH_HYPRE
# `mpirun -np 2 mpmbench matrix run`: rank 0 hands the cells out to both
# ranks (itself included) and writes cells.csv; the union of the cells must
# equal a serial run's, row for row in everything but times. One cell uses
# BoomerAMG, whose adapter calls MPI_Init in the child: the child must start
# as an MPI singleton of its own (the launcher's variables scrubbed), not
# join the runner's job. An error on one rank only (injected with
# MPM_TEST_FAIL_RANK: rank 1 when handed its first cell, or rank 0 at the
# start) ends the study on every rank with exit 1 and one error line naming
# the rank, without a hang or MPI_Abort, and no cell process left behind.
# Skipped (exit 77) when mpirun is missing.
. "$(dirname "$0")/../common/shell_harness.sh"

command -v mpirun >/dev/null || skip "mpirun not found (Debian package openmpi-bin)"
cat >"$tmp/m.json" <<'EOF'
{"name": "mpi", "defaults": {"scene": "stretched-box", "scale": 5, "frames": 1, "threads": 1},
 "axes": {"solver": ["hot", "pn-pcg", "pn-amg-pcg", "lbfgs-h"], "eps": [1e-7, 1e-8]}}
EOF
"$bin" matrix run "$tmp/m.json" --out "$tmp/serial" >"$tmp/serial.txt" 2>&1
check "serial run exit 0" test $? -eq 0
mpirun_ranks -np 2 "$bin" matrix run "$tmp/m.json" --out "$tmp/mpi" \
  >"$tmp/mpi.txt" 2>"$tmp/mpi.err"
rc=$?
check "mpirun -np 2 exit 0 (got $rc: $(head -c 300 "$tmp/mpi.err"))" test "$rc" -eq 0
check "announced on 2 ranks" grep -q "8 to run on 2 ranks" "$tmp/mpi.txt"
check "rank 1 ran cells" grep -q "(rank 1)$" "$tmp/mpi.txt"
check "rank 0 ran cells" grep -qE "^\[[0-9]/8\] .* s( \(machine busy\))?$" "$tmp/mpi.txt"
python3 - "$tmp/serial/cells.csv" "$tmp/mpi/cells.csv" >"$tmp/cmp.txt" 2>&1 <<'PY'
import csv, sys
times = {"wall_s", "timed_wall_s", "s_per_frame", "max_frame_s", "peak_rss_mb", "startup_s", "elapsed_s",
         "cpu_s", "others_cpu_s", "load_start", "machine_busy"}
ser = {r["id"]: r for r in csv.DictReader(open(sys.argv[1]))}
got = list(csv.DictReader(open(sys.argv[2])))
assert len(got) == len({r["id"] for r in got}) == len(ser) == 8, (len(got), len(ser))
for r in got:
    a = {k: v for k, v in r.items() if k not in times}
    b = {k: v for k, v in ser[r["id"]].items() if k not in times}
    assert a == b, f"{r['id']}:\n{a}\n{b}"
    assert r["status"] == "ok" and r["converged_fraction"] == "1.000000", r
amg = [float(r["startup_s"]) for r in got if r["solver"] == "pn-amg-pcg"]
other = [float(r["startup_s"]) for r in got if r["solver"] != "pn-amg-pcg"]
# MPI_Init + HYPRE_Init are charged to startup_s, not to a step: milliseconds at least, the others microseconds
assert amg and min(amg) > 1e-3 and min(amg) > 10 * max(other), f"startup_s: AMG {amg}, others {other}"
print("ok")
PY
check "cells equal the serial run's ($(tail -1 "$tmp/cmp.txt"))" grep -qx ok "$tmp/cmp.txt"
check "the AMG cells' children ran as singletons (no MPI complaint)" bash -c "! cat '$tmp'/mpi/cells/*/stderr.txt | grep -qi mpi"
"$bin" matrix report "$tmp/mpi" >"$tmp/report.txt" 2>&1
check "report of the distributed run exit 0" test $? -eq 0
check "its report says it ran on 2 ranks" grep -q "mpirun: 2 ranks x 1 job)" "$tmp/mpi/report.md"
"$bin" matrix report "$tmp/serial" >"$tmp/report-serial.txt" 2>&1
check "the serial report says no mpirun" bash -c "! grep -q 'mpirun:' '$tmp/serial/report.md'"

# an error on one rank only
for fail in 1 0; do
  MPM_TEST_FAIL_RANK=$fail mpirun_ranks -x MPM_TEST_FAIL_RANK -np 2 "$bin" matrix run "$tmp/m.json" --out "$tmp/fail$fail" \
    >"$tmp/fail$fail.txt" 2>"$tmp/fail$fail.err"
  rc=$?
  check "rank $fail fails: exit 1, not a hang (124) or an abort (got $rc: $(head -c 300 "$tmp/fail$fail.err"))" test "$rc" -eq 1
  check "rank $fail fails: one error line naming it ($(cat "$tmp/fail$fail.err"))" \
    test "$(grep -c "^mpmbench: error: rank $fail: injected failure" "$tmp/fail$fail.err")" -eq 1
  check "rank $fail fails: no MPI_Abort" bash -c "! grep -q 'MPI_ABORT was invoked' '$tmp/fail$fail.err'"
done
check "no cell process outlives the failed studies" bash -c "! pgrep -f -- '--out $tmp/fail[01]/cells' >/dev/null"
finish
