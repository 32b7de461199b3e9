#!/usr/bin/env bash
# Robustness of the command line (issue 12): results independent of the
# thread count (257 and more threads equal 2), thread counts and output
# paths checked before any work, flags named in their messages, the
# reference CFL rule's step sequence on bar3.
. "$(dirname "$0")/../common/shell_harness.sh"
export OMP_WAIT_POLICY=passive

# bar3 thinned to 2.7 dx across (9k particles at its own dx 0.0075): small
# runs whose stiff middle makes every step iterate
thin=()
for k in 0 1 2; do
  thin+=(--set "objects.$k.shape.min.0=1.99" --set "objects.$k.shape.min.2=1.99"
         --set "objects.$k.shape.max.0=2.01" --set "objects.$k.shape.max.2=2.01")
done

# --- thread counts ---------------------------------------------------------
# the same run with 2 and 300 threads: every column but the timings equal
# (more than the 256 per-thread slots the sums used to have)
strip() { cut -d, -f1-14 "$1/steps.csv"; cut -d, -f1-6,8,9 "$1/frames.csv"; }
for solver in pn-pcg hot; do
  "$bin" run --scene bar3 --solver $solver --frames 1 --quiet "${thin[@]}" --threads 2 --out "$tmp/t2-$solver"
  rc2=$?
  "$bin" run --scene bar3 --solver $solver --frames 1 --quiet "${thin[@]}" --threads 300 --out "$tmp/t300-$solver"
  rc300=$?
  check "$solver: 2 and 300 threads exit 0" test "$rc2$rc300" = 00
  check "$solver: 300 threads give the 2-thread results exactly" cmp -s <(strip "$tmp/t2-$solver") <(strip "$tmp/t300-$solver")
  check "$solver: the steps iterate (outer iterations > 2)" awk -F, 'NR>1 && $10<=2{bad=1} END{exit bad}' "$tmp/t2-$solver/steps.csv"
done
common=(run --scene drop --solver pn-pcg --scale 2 --frames 2 --quiet)
expect_input_error "--threads '0': expected an integer number of threads in \[1, 1024\]" "${common[@]}" --threads 0 --out "$tmp/x"
expect_input_error "--threads '1025'" "${common[@]}" --threads 1025 --out "$tmp/x"
expect_input_error "--threads '2.5'" "${common[@]}" --threads 2.5 --out "$tmp/x"
expect_input_error "--threads '4096'" render --scene drop --threads 4096 --out "$tmp/x.png"
# OMP_NUM_THREADS: OpenMP's runtime may print its own warning first; ours is the last line
for v in 0 1025 abc; do
  OMP_NUM_THREADS=$v "$bin" "${common[@]}" --out "$tmp/env" >/dev/null 2>"$tmp/env.err"
  rc=$?
  check "OMP_NUM_THREADS=$v: exit 2 naming it" bash -c "[ $rc -eq 2 ] && tail -1 '$tmp/env.err' | grep -q \"OMP_NUM_THREADS='$v'\""
  check "OMP_NUM_THREADS=$v: no output written" test ! -e "$tmp/env"
done

# --- output paths, before any work -----------------------------------------
touch "$tmp/afile"
expect_input_error "--out '': expected a directory name" "${common[@]}" --out ""
expect_input_error "--particles '': expected a directory name" "${common[@]}" --out "$tmp/p" --particles ""
expect_input_error "--out '.*afile': exists and is not a directory" "${common[@]}" --out "$tmp/afile"
expect_input_error "--particles '.*afile/sub': '.*afile' is not a directory" "${common[@]}" --out "$tmp/p2" --particles "$tmp/afile/sub"
check "a refused --particles made no output directory" test ! -e "$tmp/p2"
"$bin" "${common[@]}" --out "$tmp/new/deep/dir" --particles "$tmp/new/ply"
check "missing directories are created" test -f "$tmp/new/deep/dir/steps.csv" -a -f "$tmp/new/ply/frame_0001.ply"

# --- messages naming the real field ----------------------------------------
expect_input_error "--width '100000': expected an image size in pixels in \[1, 16384\]" render --scene drop --width 100000 --out "$tmp/w.png"
expect_input_error "--height '0'" render --scene drop --height 0 --out "$tmp/w.png"
expect_input_error "/tmp: is a directory, not a scene file" run --scene /tmp --solver pn-pcg --out "$tmp/x"
expect_input_error "/dev/null: not a regular file" run --scene /dev/null --solver pn-pcg --out "$tmp/x"
expect_input_error "dx: expected at most the domain's smallest extent 1 m, got 1e\+308" run --scene drop --solver pn-pcg --set dx=1e308 --out "$tmp/x"
expect_input_error "fps: expected a frame rate whose frame length 1/fps is finite, got 1e-310" "${common[@]}" --set fps=1e-310 --out "$tmp/x"
expect_input_error "max_dt: expected at least min_dt" "${common[@]}" --set max_dt=1e-12 --out "$tmp/x"
expect_input_error "objects.0: ppc 8 at dx 0.04 m \(dx times --scale 2\).*above the particle budget 100 \(--max-particles\)" "${common[@]}" --max-particles 100 --out "$tmp/x"
expect_input_error "--max-particles '1.5': expected a whole number" "${common[@]}" --max-particles 1.5 --out "$tmp/x"
expect_input_error "dx times --scale 0.05.*particle budget" run --scene drop --solver pn-pcg --scale 0.05 --out "$tmp/x"
expect_input_error "colliders.1.motion.0: collider \"top_cap\" moves at a non-finite speed" run --scene bar3 --solver pn-pcg --set colliders.1.motion.0.angular_velocity_deg.1=1e308 --out "$tmp/x"

# --- a particle reaching a domain wall stays in the domain (F = 0.01 I explodes the box) ---
"$bin" run --scene drop --solver pn-pcg --scale 2 --frames 2 --quiet --out "$tmp/boom" \
  --set 'objects.0.initial_F={"type":"random_diagonal","min":0.01,"max":0.01}' 2>"$tmp/boom.err"
rc=$?  # before the description's $(...), which resets $?
check "exploding box with domain walls: exit 0 ($(cat "$tmp/boom.err"))" test $rc -eq 0

# --- the reference CFL rule (SPEC 12) on bar3 at dx 0.0075 -----------------
# the thin bar keeps the run small; the collider speed sets dt
bar=(run --scene bar3 --solver pn-pcg --frames 1 --quiet --set materials.middle.E=1e5 "${thin[@]}")
"$bin" "${bar[@]}" --set cfl_rule=reference --out "$tmp/ref"
check "bar3, reference rule: 9 steps in the first frame" test "$(awk -F, 'NR>1 && $3==0' "$tmp/ref/steps.csv" | wc -l)" -eq 9
check "bar3, reference rule: dt within 1e-4 of 0.0024565 s" \
  awk -F, 'NR==2{d=$6/0.0024565-1; if (d<0) d=-d; exit !(d<1e-4)}' "$tmp/ref/steps.csv"
"$bin" "${bar[@]}" --out "$tmp/paper"
check "bar3, paper rule (default): a longer first step" awk -F, 'NR==2{exit !($6>0.004)}' "$tmp/paper/steps.csv"
finish
