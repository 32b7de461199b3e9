#!/usr/bin/env bash
# Command-line contract: listings, a short run writing the CSV files with the
# documented columns, and bad input giving exit status 2 with one line that
# names the problem.
. "$(dirname "$0")/../common/shell_harness.sh"

"$bin" list solvers >"$tmp/solvers"
check "list solvers has pn-pcg" grep -q "^pn-pcg " "$tmp/solvers"
check "list solvers has pn-pcg-mf" grep -q "^pn-pcg-mf " "$tmp/solvers"
check "list solvers has pn-sgs-pcg" grep -q "^pn-sgs-pcg " "$tmp/solvers"
"$bin" list scenes >"$tmp/scenes"
for s in drop bar3 stretched-box; do check "list scenes has $s" grep -q "^$s " "$tmp/scenes"; done
# list scenes --particles: the count a run of the scene starts with
"$bin" list scenes --particles --scale 4 >"$tmp/counts"
check "list scenes --particles: exit 0" test $? -eq 0
check "list scenes --particles: one row per scene and a header" test "$(wc -l <"$tmp/counts")" -eq "$(($(wc -l <"$tmp/scenes") + 1))"
"$bin" run --scene stretched-box --scale 4 --solver pn-pcg --frames 1 --quiet --out "$tmp/count-run" >/dev/null 2>&1
want_n=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['particles'])" "$tmp/count-run/run.json")
check "list scenes --particles: stretched-box's count is the run's ($want_n)" grep -qE "^stretched-box +$want_n\$" "$tmp/counts"
check "list scenes --particles: a source scene says more come" grep -qE "^sauce +[0-9]+  \(at the start; its sources add more\)" "$tmp/counts"
expect_input_error "list scenes --scale: needs --particles" list scenes --scale 3

# a short run writes the three CSV files with the documented headers
"$bin" run --scene drop --solver pn-pcg --frames 1 --out "$tmp/run" --history --quiet
check "run exit 0" test $? -eq 0
check "steps.csv header" grep -qx "scene,solver,frame,step,t,dt,particles,active_nodes,hessian_blocks,outer_iters,linear_iters,ls_evals,residual,status,wall_s,p2g_s,assemble_s,setup_s,solve_s,linesearch_s,g2p_s,threads,inner_iters,max_energy_rise,err_h,e_gap,err_v_max,ref_solver,ref_status,ref_s,reason" "$tmp/run/steps.csv"
check "frames.csv header" grep -qx "scene,solver,frame,steps,outer_iters,linear_iters,wall_s,max_residual,status,threads,inner_iters,complete,pos_rms,pos_max,vel_rms,reason" "$tmp/run/frames.csv"
check "iters.csv header" grep -qx "frame,step,iter,elapsed_s,residual,energy" "$tmp/run/iters.csv"
check "every step converged" awk -F, 'NR>1 && $14!="converged"{bad=1} END{exit bad}' "$tmp/run/steps.csv"
check "frames.csv has one row" test "$(wc -l <"$tmp/run/frames.csv")" -eq 2
check "run.json written" grep -q '"solver": "pn-pcg"' "$tmp/run/run.json"

# --particles: one binary PLY per frame with position, velocity, material id
"$bin" run --scene drop --solver pn-pcg --frames 2 --quiet --out "$tmp/plyrun" --particles "$tmp/ply"
check "run with --particles exit 0" test $? -eq 0
check "one PLY per frame" test -f "$tmp/ply/frame_0001.ply" -a -f "$tmp/ply/frame_0002.ply" -a ! -e "$tmp/ply/frame_0003.ply"
python3 - "$tmp/ply/frame_0002.ply" "$tmp/plyrun/steps.csv" >"$tmp/ply.check" 2>&1 <<'PY'
import csv, struct, sys
data = open(sys.argv[1], "rb").read()
head, body = data.split(b"end_header\n", 1)
lines = head.decode().splitlines()
assert lines[0] == "ply" and lines[1] == "format binary_little_endian 1.0", lines[:2]
n = int([l for l in lines if l.startswith("element vertex")][0].split()[2])
props = [l.split()[2] for l in lines if l.startswith("property")]
assert props == ["x", "y", "z", "vx", "vy", "vz", "material"], props
steps = list(csv.DictReader(open(sys.argv[2])))
assert n == int(steps[-1]["particles"]), (n, steps[-1]["particles"])
assert len(body) == n * 28, (len(body), n)
recs = [struct.unpack_from("<6fi", body, 28 * k) for k in range(n)]
ys = [r[1] for r in recs]
# the box starts at y in [0.2, 0.4] and falls: after 2 frames it is lower, still above the ground
assert 0.1 < min(ys) < 0.2 and max(ys) < 0.4, (min(ys), max(ys))
assert all(r[4] < 0 for r in recs[:100]), "falling particles move down"
assert {r[6] for r in recs} == {0}, "one material"
print("ok")
PY
check "PLY header, count and contents ($(tail -1 "$tmp/ply.check"))" grep -qx ok "$tmp/ply.check"

# progress: a line with frame, step, iteration and ETA on a terminal only
"$bin" run --scene drop --solver pn-pcg --frames 1 --out "$tmp/quiet" >/dev/null 2>"$tmp/pipe.err"
check "no progress into a pipe" test ! -s "$tmp/pipe.err"
if command -v script >/dev/null; then
  env -u CI script -qc "'$bin' run --scene drop --solver pn-pcg --frames 1 --out '$tmp/tty'" /dev/null >"$tmp/tty.out"
  check "progress on a terminal" grep -q "frame 1/1  step 0  iter 0  residual .* ETA" "$tmp/tty.out"
  CI=1 script -qc "'$bin' run --scene drop --solver pn-pcg --frames 1 --out '$tmp/tty-ci'" /dev/null >"$tmp/tty-ci.out"
  check "no progress with CI set" bash -c "! grep -q ETA '$tmp/tty-ci.out'"
else
  echo "progress on a terminal: no 'script' command, skipped"
fi

# bench: a table, then one key=value line per figure, all positive
"$bin" bench all --scene drop --threads 2 >"$tmp/bench.out" 2>&1
check "bench exit 0" test $? -eq 0
for key in spmv_gbs stream_gbs spmv_stream_ratio assemble_particles_per_s p2g_particles_per_s threads \
  g2p_particles_per_s hessvec_particles_per_s p2g_stream_fraction p2g_peak_fraction g2p_flops_per_particle \
  stream_dram_gbs peak_gflops energy_particles_per_s energy_peak_fraction gradient_particles_per_s \
  tangent_particles_per_s; do
  check "bench reports $key > 0" awk -F= -v k="$key" '$1 == k && $2 + 0 > 0 {found = 1} END {exit !found}' "$tmp/bench.out"
done
check "bench: particles of drop" grep -qx "particles=6938" "$tmp/bench.out"
expect_input_error "bench.*frobnicate|unknown" bench frobnicate --scene drop
# --transfer mls is --set transfer=mls; the MLS kernels report the same figures
"$bin" bench p2g --scene drop --threads 1 --transfer mls >"$tmp/bench-mls.out" 2>&1
check "bench --transfer mls exit 0" test $? -eq 0
check "bench --transfer mls: transfer=mls" grep -qx "transfer=mls" "$tmp/bench-mls.out"
check "bench --transfer mls: fused P2G" grep -q "MLS fused" "$tmp/bench-mls.out"
expect_input_error "transfer.*pic" bench p2g --scene drop --transfer pic

# run.json records every option the solver consulted with the value in effect
"$bin" run --scene stretched-box --scale 3.6 --solver hot --solver-opt embedding=quadratic --frames 1 --quiet \
  --out "$tmp/hotq-opt"
check "run.json: given option" grep -q '"embedding": "quadratic"' "$tmp/hotq-opt/run.json"
check "run.json: default option" grep -q '"window": "8"' "$tmp/hotq-opt/run.json"
# ... and hot with the quadratic embedding is the hot-quadratic preset, step for step
"$bin" run --scene stretched-box --scale 3.6 --solver hot-quadratic --frames 1 --quiet --out "$tmp/hotq"
check "embedding=quadratic reproduces hot-quadratic" \
  test "$(cut -d, -f10-13 "$tmp/hotq-opt/steps.csv")" = "$(cut -d, -f10-13 "$tmp/hotq/steps.csv")"

# bad usage and bad input
expect_input_error "unknown solver 'nosuch'" run --scene drop --solver nosuch
expect_input_error "nosuchscene" run --scene nosuchscene --solver pn-pcg
expect_input_error "unknown command" frobnicate
expect_input_error "--frames" run --scene drop --solver pn-pcg --frames -3
expect_input_error "--eps" run --scene drop --solver pn-pcg --eps abc
expect_input_error "unknown option" run --scene drop --solver pn-pcg --bogus
expect_input_error "materials.ends.E|E.*-5" run --scene bar3 --solver pn-pcg --set materials.ends.E=-5
expect_input_error "nu" run --scene bar3 --solver pn-pcg --set materials.middle.nu=0.5
# a solver option nobody reads is a typo, not a silent default
expect_input_error "hot has no option 'level'.*levels" run --scene drop --solver hot --solver-opt level=2
expect_input_error "pn-pcg has no option 'window'" run --scene drop --solver pn-pcg --solver-opt window=4
expect_input_error "levels=x: expected a number" run --scene drop --solver hot --solver-opt levels=x

printf '{ "name": "broken", \n "dx": 0.1,, }\n' >"$tmp/malformed.json"
expect_input_error "malformed.json" run --scene "$tmp/malformed.json" --solver pn-pcg
python3 - "$src/experiments/scenes/drop.json" "$tmp" <<'PY'
import json, sys
src, tmp = sys.argv[1], sys.argv[2]
base = json.load(open(src))
def write(name, scene):
    json.dump(scene, open(f"{tmp}/{name}.json", "w"), indent=1)
s = json.loads(json.dumps(base)); del s["dx"]; write("missing", s)
s = json.loads(json.dumps(base)); next(iter(s["materials"].values()))["E"] = 0; write("zeroE", s)
s = json.loads(json.dumps(base)); next(iter(s["materials"].values()))["nu"] = 0.7; write("badnu", s)
s = json.loads(json.dumps(base)); s["gravity"] = [0, "NaN", 0]; write("nan", s)
PY
expect_input_error "missing.json.*dx" run --scene "$tmp/missing.json" --solver pn-pcg
expect_input_error "zeroE.json.*E" run --scene "$tmp/zeroE.json" --solver pn-pcg
expect_input_error "badnu.json.*nu" run --scene "$tmp/badnu.json" --solver pn-pcg
expect_input_error "nan.json.*gravity" run --scene "$tmp/nan.json" --solver pn-pcg
printf '{"name":"x","dx":0.1,"frames":1,"fps":24,"domain":{"min":[0,0,0],"max":[1,1,1]},"materials":{"m":{"E":1e5,"nu":0.3,"density":1000}},"objects":[{"material":"m","ppc":8,"shape":{"type":"sphere","center":[0.5,0.5,0.5],"radius":NaN}}]}' >"$tmp/nanlit.json"
expect_input_error "nanlit.json" run --scene "$tmp/nanlit.json" --solver pn-pcg

finish
