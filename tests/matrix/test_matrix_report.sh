#!/usr/bin/env bash
# `mpmbench matrix report DIR` on a hand-made result directory with known
# answers: s/frame over the timed window, total and max per-frame speedup
# against the baseline, iterations over the window, worst status, the
# performance-profile ratios (only over the cases in which every solver
# ended ok with every step converged), the multigrid table, and figures that
# decode as PNGs one or two columns wide (700 or 1,420 pixels at 200 dpi:
# frame times, convergence, stiffness, profile, speedup), each with an SVG.
. "$(dirname "$0")/../common/shell_harness.sh"

d="$tmp/toy"
mkdir -p "$d/cells"
cat >"$d/matrix.json" <<'EOF'
{"name": "toy", "description": "hand-made", "baseline": "base", "report_mg_levels": true,
 "named_axes": [{"name": "stiffness", "kind": "set",
                 "values": [{"label": "1e+05", "settings": {"materials.middle.E": "1e+05"}},
                            {"label": "1e+07", "settings": {"materials.middle.E": "1e+07"}}]}]}
EOF
# cells.csv has a column the report does not know (read by name)
echo "id,scene,solver,eps,scale,threads,frames_asked,first_timed_frame,stiffness,set,solver_opts,status,exit,frames,steps,outer_iters,linear_iters,inner_iters,wall_s,timed_frames,timed_wall_s,s_per_frame,max_frame_s,max_residual,converged_fraction,worst_solve_status,particles,peak_rss_mb,startup_s,elapsed_s,future" >"$d/cells.csv"
# cell ID SCENE SOLVER E FIRST STATUS CONVERGED_FRACTION WORST "wall outer linear status" per frame...
cell() {
  local id=$1 scene=$2 solver=$3 e=$4 first=$5 status=$6 conv=$7 worst=$8
  shift 8
  echo "$id,$scene,$solver,1e-07,2,2,4,$first,$e,materials.middle.E=$e,,$status,0,$#,0,0,0,,0,0,0,0,0,1e-8,$conv,$worst,100,10,0.1,1,x" >>"$d/cells.csv"
  mkdir -p "$d/cells/$id"
  # frames.csv with the columns in another order and one more, as a newer run loop may write
  echo "frame,scene,solver,steps,linear_iters,outer_iters,inner_iters,wall_s,max_residual,status,threads" >"$d/cells/$id/frames.csv"
  local f=0
  for fr in "$@"; do
    set -- $fr
    echo "$f,$scene,$solver,2,$3,$2,0,$1,5e-8,$4,2" >>"$d/cells/$id/frames.csv"
    f=$((f + 1))
  done
}
cell c1 toy base 1e+05 1 ok 1.0 converged "1.0 0 0 converged" "4.0 10 100 converged" "4.0 10 100 converged" "4.0 10 100 converged"
cell c2 toy fast 1e+05 1 ok 0.75 capped "1.0 0 0 converged" "1.0 20 10 converged" "1.0 20 10 converged" "2.0 20 10 capped"
cell c3 toy base 1e+07 1 ok 1.0 converged "1.0 0 0 converged" "2.0 5 50 converged" "2.0 5 50 converged" "2.0 5 50 converged"
cell c4 toy fast 1e+07 1 timeout 1.0 converged "1.0 0 0 converged" "0.5 3 3 converged"
cell c5 toy2 base 1e+05 0 ok 1.0 converged "2.0 8 80 converged"
cell c6 toy2 fast 1e+05 0 ok 1.0 converged "1.0 9 9 converged"
# steps.csv of one cell: dt over the timed window (frames 1-3) only
printf 'frame,step,dt,status\n0,0,0.5,converged\n1,0,0.004,converged\n2,0,0.001,converged\n2,1,0.003,converged\n3,0,0.004,converged\n' >"$d/cells/c1/steps.csv"
for id in c1 c2; do
  echo "frame,step,iter,elapsed_s,residual,energy" >"$d/cells/$id/iters.csv"
  for k in 0 1 2 3; do echo "1,0,$k,0.$k,1e-$((k + 3)),-1.0" >>"$d/cells/$id/iters.csv"; done
done
printf 'level,nodes,blocks,blocks_per_row_avg,blocks_per_row_max\n0,15002,1203000,80.19,125\n1,3122,201000,64.41,125\n' >"$d/cells/c1/mg_levels.csv"

"$bin" matrix report "$d" >"$tmp/report.out" 2>"$tmp/report.err"
rc=$?
check "report exit 0 ($(head -c 300 "$tmp/report.err"))" test $rc -eq 0
check "report files" test -s "$d/report.md" -a -s "$d/report.csv" -a -s "$d/profile.csv"
field() { # case solver column
  python3 - "$d/report.csv" "$@" <<'PY'
import csv, sys
r = [x for x in csv.DictReader(open(sys.argv[1])) if x["case"] == sys.argv[2] and x["solver"] == sys.argv[3]]
print(r[0][sys.argv[4]] if len(r) == 1 else f"{len(r)} rows")
PY
}
check "base: 12 s over frames 1-3 = 4 s/frame" test "$(field "toy stiffness=1e+05" base s_per_frame)" = "4.000000"
check "fast: 4 s over 3 frames" test "$(field "toy stiffness=1e+05" fast s_per_frame)" = "1.333333"
check "fast: total speedup 12/4 = 3" test "$(field "toy stiffness=1e+05" fast speedup_total)" = "3.000000"
check "fast: max per-frame speedup max(4/1, 4/1, 4/2) = 4" test "$(field "toy stiffness=1e+05" fast speedup_max_frame)" = "4.000000"
check "baseline against itself: 1" test "$(field "toy stiffness=1e+05" base speedup_total)" = "1.000000"
check "iterations over the timed window" test "$(field "toy stiffness=1e+05" fast outer_iters),$(field "toy stiffness=1e+05" fast linear_iters)" = "60,30"
check "linear per step (HOT Table 3): 300 / 6" test "$(field "toy stiffness=1e+05" base linear_per_step)" = "50.000000"
check "min dt over the timed window (frame 0 not timed)" test "$(field "toy stiffness=1e+05" base min_dt)" = "1.000000e-03"
check "average dt over the timed window: 0.012 / 4" test "$(field "toy stiffness=1e+05" base avg_dt)" = "3.000000e-03"
check "no steps.csv: no dt" test "$(field "toy stiffness=1e+05" fast min_dt)" = ""
check "max residual over the timed window" test "$(field "toy stiffness=1e+05" base max_residual)" = "5.000000e-08"
check "worst status of frames" test "$(field "toy stiffness=1e+05" fast worst_status)" = capped
check "a timed-out cell: no speedup" test "$(field "toy stiffness=1e+07" fast speedup_total)" = ""
check "a timed-out cell: worst status timeout" test "$(field "toy stiffness=1e+07" fast worst_status)" = timeout
check "second scene: speedup 2" test "$(field "toy2 stiffness=1e+05" fast speedup_total)" = "2.000000"
check "markdown table row, the capped cell marked" grep -q "| fast | ok not converged | 3 | 1.33 | 3.00 not converged | 4.00 | 60 | 30 | 5.00 | capped |" "$d/report.md"
check "per-scene window noted" grep -q "^(first_timed_frame=1)" "$d/report.md"
check "overview: s/frame per solver" grep -q "^| toy stiffness=1e+05 | 4.00 | 1.33 not converged |$" "$d/report.md"
check "overview: a cell that did not end ok" grep -q "^| toy stiffness=1e+07 | 2.00 | - |$" "$d/report.md"
check "overview: speedups total / max per frame" grep -q "^| toy stiffness=1e+05 | 3.00 not converged / 4.00 |$" "$d/report.md"
python3 - "$d/profile.csv" >"$tmp/profile.txt" <<'PY'
import csv, sys
got = {(r["case"], r["solver"]): r["ratio"] for r in csv.DictReader(open(sys.argv[1]))}
want = {("toy2 stiffness=1e+05", "base"): "2.000000", ("toy2 stiffness=1e+05", "fast"): "1.000000"}
print("ok" if got == want else f"got {got}")
PY
check "profile ratios: only the case both solvers converged ($(cat "$tmp/profile.txt"))" grep -qx ok "$tmp/profile.txt"
check "profile: the cases left out, with the reason" grep -q "^- toy stiffness=1e+05: fast did not converge every step" "$d/report.md"
check "multigrid table" grep -q "| 0 | 80.2 / 125 (15,002 nodes) |" "$d/report.md"
check "stiffness figure in the report" grep -q "^!\[time and iterations against stiffness" "$d/report.md"

# every figure is a PNG that decodes (all IDAT data inflates to height rows) at 800 x 500
for kind in profile speedup frames_ convergence_ stiffness_; do
  check "a $kind figure" bash -c "ls '$d'/figures/$kind*.png >/dev/null 2>&1"
done
check "no frame plot for one-frame cases" bash -c "! ls '$d'/figures/frames_*toy2* >/dev/null 2>&1"
python3 - "$d"/figures/*.png >"$tmp/png.txt" 2>&1 <<'PY'
import struct, sys, zlib
for path in sys.argv[1:]:
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        assert zlib.crc32(kind + body) == struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])[0], f"{path}: CRC"
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    w, h, depth, color = ihdr[:4]
    channels = {2: 3, 6: 4, 0: 1, 4: 2}[color]
    raw = zlib.decompress(idat)
    assert len(raw) == h * (1 + w * channels * depth // 8), f"{path}: {len(raw)} bytes"
    assert w in (700, 1420) and 300 < h < 1600, f"{path}: {w} x {h}"
print(f"ok: {len(sys.argv) - 1} figures")
PY
check "PNGs decode, one or two columns wide ($(tail -1 "$tmp/png.txt"))" grep -q "^ok" "$tmp/png.txt"
check "an SVG beside every PNG" bash -c "for p in '$d'/figures/*.png; do grep -q '<svg' \"\${p%.png}.svg\" || exit 1; done"

# bad input: one line with the common prefix, exit 2
mkdir -p "$tmp/empty"
"$bin" matrix report "$tmp/empty" >/dev/null 2>"$tmp/err"
check "no cells.csv: exit 2, one line" test $? -eq 2 -a "$(wc -l <"$tmp/err")" -eq 1
check "no cells.csv: message with the common prefix" grep -q "^mpmbench: error: matrix report: .*empty/cells.csv: not found" "$tmp/err"
# a Python with matplotlib is found: a python3 first on PATH that cannot import it (a virtual
# environment without it), MPM_PYTHON unset, and the report still runs (with /usr/bin/python3);
# MPM_PYTHON without matplotlib falls back with a note; no usable Python (matplotlib hidden from
# every interpreter): one line with the common prefix naming what was tried and MPM_PYTHON, exit 2
mkdir -p "$tmp/fakebin" "$tmp/nompl/matplotlib"
printf '#!/bin/sh\necho "ModuleNotFoundError: No module named matplotlib" >&2\nexit 1\n' >"$tmp/fakebin/python3"
chmod +x "$tmp/fakebin/python3"
echo 'raise ImportError("hidden for the test")' >"$tmp/nompl/matplotlib/__init__.py"
if /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then
  env -u MPM_PYTHON PATH="$tmp/fakebin:$PATH" "$bin" matrix report "$d" >"$tmp/out" 2>"$tmp/err"
  rc=$?
  check "a python3 without matplotlib first on PATH, MPM_PYTHON unset: the report runs ($(head -c 300 "$tmp/err"))" \
    test $rc -eq 0 -a ! -s "$tmp/err"
  MPM_PYTHON="$tmp/fakebin/python3" "$bin" matrix report "$d" >"$tmp/out" 2>"$tmp/err"
  rc=$?
  check "MPM_PYTHON without matplotlib: falls back, with a note ($(head -c 300 "$tmp/err"))" \
    test $rc -eq 0 -a "$(grep -c "^mpmbench: note: MPM_PYTHON=$tmp/fakebin/python3 (no matplotlib); using " "$tmp/err")" -eq 1
else
  echo "(skipped the fallback checks: /usr/bin/python3 has no matplotlib)"
fi
MPM_PYTHON="$tmp/fakebin/python3" PYTHONPATH="$tmp/nompl" PATH="$tmp/fakebin:$PATH" \
  "$bin" matrix report "$d" >"$tmp/out" 2>"$tmp/err"
rc=$?
check "no usable Python: exit 2, one line (exit $rc, $(wc -l <"$tmp/err") lines)" test $rc -eq 2 -a "$(wc -l <"$tmp/err")" -eq 1
check "no usable Python: the common prefix, what was tried, the package, MPM_PYTHON ($(cat "$tmp/err"))" grep -q \
  "^mpmbench: error: matrix report: no Python that can import matplotlib (tried MPM_PYTHON=$tmp/fakebin/python3 (no matplotlib), /usr/bin/python3 (no matplotlib)); .*python3-matplotlib.*set MPM_PYTHON" \
  "$tmp/err"
MPM_PYTHON=/no/such/python PYTHONPATH="$tmp/nompl" "$bin" matrix report "$d" >"$tmp/out" 2>"$tmp/err"
check "no usable Python: a missing MPM_PYTHON named as such ($(cat "$tmp/err"))" \
  grep -q "(tried MPM_PYTHON=/no/such/python (not found), " "$tmp/err"
# the script run directly by a Python without matplotlib: the same prefix and status
PYTHONPATH="$tmp/nompl" "${MPM_PYTHON:-python3}" "$src/scripts/matrix_report.py" "$d" >/dev/null 2>"$tmp/err"
rc=$?
check "the script without matplotlib: exit 2, one line naming the package and MPM_PYTHON ($(cat "$tmp/err"))" \
  test $rc -eq 2 -a "$(wc -l <"$tmp/err")" -eq 1 -a \
  "$(grep -c '^mpmbench: error: matrix report: .*python3-matplotlib.*MPM_PYTHON' "$tmp/err")" -eq 1
expect_input_error "matrix report: expected a result directory" matrix report
finish
