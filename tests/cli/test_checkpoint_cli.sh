#!/usr/bin/env bash
# run --checkpoint-at / --from (experiments/io/checkpoint.h): on sauce (a
# source emitting, von Mises plasticity, a moving source collider), a run of
# frames 0..8 writing checkpoints at frames 0 and 5 and a run continued from
# frame 5 give identical steps.csv and frames.csv rows from frame 5 on (every
# column but the times), at 1 and 2 threads; from frame 0 the whole run is
# reproduced. --checkpoint-every-s leaves one resume checkpoint (at the last
# frame's start when every frame passes the interval) from which the run
# goes on bit for bit, and no partial file. A corrupt, truncated or
# mismatched checkpoint (another scale,
# another --set), a list frame past the end and --from with nothing left to
# run are one-line errors with exit 2, before any output.
. "$(dirname "$0")/../common/shell_harness.sh"
S=(run --scene sauce --scale 4 --solver pn-pcg --quiet)
run() { "$bin" "${S[@]}" "$@"; }
same_rows() { # FULL PART FIRST_FRAME FILE: PART's rows equal FULL's from FIRST_FRAME on
  python3 - "$@" <<'PY'
import csv, sys
full, part, first, name = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
f = [r for r in csv.DictReader(open(f"{full}/{name}")) if int(r["frame"]) >= first]
p = list(csv.DictReader(open(f"{part}/{name}")))
keys = [k for k in p[0] if not k.endswith("_s") and k != "threads"] if p else []
assert len(f) == len(p) > 0, (len(f), len(p))
for a, b in zip(f, p):
    d = [k for k in keys if a[k] != b[k]]
    assert not d, (name, a["frame"], d[:3], [a[k] for k in d[:3]], [b[k] for k in d[:3]])
print("ok")
PY
}
run --frames 9 --checkpoint-at 0,5 --threads 2 --out "$tmp/full"
check "full run with checkpoints: exit 0" test $? -eq 0
check "checkpoints written at frames 0 and 5" test -s "$tmp/full/checkpoints/frame_0000.ckpt" -a -s "$tmp/full/checkpoints/frame_0005.ckpt"
for th in 1 2; do
  run --frames 9 --threads $th --from "$tmp/full/checkpoints/frame_0005.ckpt" --out "$tmp/from5-$th"
  check "from frame 5 ($th threads): exit 0" test $? -eq 0
  for f in steps.csv frames.csv; do
    out=$(same_rows "$tmp/full" "$tmp/from5-$th" 5 $f 2>&1 | tail -1)
    check "from frame 5 ($th threads): $f equals the full run's from frame 5 ($out)" test "$out" = ok
  done
done
run --frames 9 --threads 2 --from "$tmp/full/checkpoints/frame_0000.ckpt" --out "$tmp/from0"
out=$(same_rows "$tmp/full" "$tmp/from0" 0 steps.csv 2>&1 | tail -1)
check "from frame 0: the whole run ($out)" test "$out" = ok
check "run.json records where it started" python3 -c "
import json, sys; c = json.load(open('$tmp/from5-1/run.json'))['checkpoints']
sys.exit(not (c['first_frame'] == 5 and c['from'].endswith('frame_0005.ckpt') and c['at'] is None))"

run --frames 9 --threads 2 --checkpoint-every-s 1e-9 --out "$tmp/every"
check "--checkpoint-every-s: exit 0" test $? -eq 0
check "--checkpoint-every-s: one resume checkpoint, no partial file" \
  test "$(ls "$tmp/every/checkpoints")" = resume.ckpt
run --frames 9 --threads 2 --from "$tmp/every/checkpoints/resume.ckpt" --out "$tmp/from-resume"
check "from the resume checkpoint: exit 0" test $? -eq 0
out=$(same_rows "$tmp/full" "$tmp/from-resume" 8 steps.csv 2>&1 | tail -1)
check "from the resume checkpoint: the last frame's rows, as the full run's ($out)" test "$out" = ok
check "run.json records the interval" python3 -c "
import json, sys; sys.exit(json.load(open('$tmp/every/run.json'))['checkpoints']['every_s'] != 1e-9)"
expect_input_error "--checkpoint-every-s '0': expected seconds in \\(0, 1e9\\]" "${S[@]}" --checkpoint-every-s 0 --out "$tmp/x10"
expect_input_error "--sample-frames: not with --checkpoint-every-s" "${S[@]}" --checkpoint-every-s 5 \
  --sample-from "$tmp/full/checkpoints" --sample-frames 5 --out "$tmp/x11"

ck="$tmp/full/checkpoints/frame_0005.ckpt"
head -c 200 "$ck" >"$tmp/short.ckpt"
python3 -c "
import sys; b = bytearray(open('$ck', 'rb').read()); b[len(b) // 2] ^= 1; open('$tmp/flip.ckpt', 'wb').write(b)"
echo "not a checkpoint" >"$tmp/text.ckpt"
expect_input_error "short.ckpt: the checkpoint is damaged or truncated" "${S[@]}" --frames 9 --from "$tmp/short.ckpt" --out "$tmp/x1"
expect_input_error "flip.ckpt: the checkpoint is damaged or truncated" "${S[@]}" --frames 9 --from "$tmp/flip.ckpt" --out "$tmp/x2"
expect_input_error "text.ckpt: not .*checkpoint" "${S[@]}" --frames 9 --from "$tmp/text.ckpt" --out "$tmp/x3"
expect_input_error "frame_0005.ckpt: written for another scene" run --scene sauce --scale 3 --solver pn-pcg --quiet --frames 9 --from "$ck" --out "$tmp/x4"
expect_input_error "frame_0005.ckpt: written for another scene" "${S[@]}" --frames 9 --set materials.sauce.E=3e5 --from "$ck" --out "$tmp/x5"
expect_input_error "starts at frame 5: --frames 5 leaves nothing to run" "${S[@]}" --frames 5 --from "$ck" --out "$tmp/x6"
expect_input_error "--checkpoint-at 2,7: frame 7 is not before the run's end \\(5 frames\\)" "${S[@]}" --frames 5 --checkpoint-at 2,7 --out "$tmp/x7"
expect_input_error "--checkpoint-at '2,,7'" "${S[@]}" --checkpoint-at 2,,7 --out "$tmp/x8"
expect_input_error "--from: not with --dt-from" "${S[@]}" --from "$ck" --dt-from "$tmp/full" --out "$tmp/x9"
check "no output folder for refused input" test ! -e "$tmp/x1" -a ! -e "$tmp/x4" -a ! -e "$tmp/x8"
finish
