#!/usr/bin/env bash
# run --sample-from DIR --sample-frames F,...: each listed frame runs alone
# from its checkpoint. On sauce (a source, plasticity, a moving collider),
# the sampled frames 1, 4 and 6 of the solver that wrote the checkpoints
# are the same rows (every column but the times) as in its own run, so each
# sample starts from exactly the written state whatever ran before it; a
# second solver gets one frames.csv row per sampled frame and run.json
# records the sample. Bad use is a one-line error, exit 2: one flag without
# the other, frames not increasing, a frame without a checkpoint, a
# checkpoint of another scale, with --frames or --from.
. "$(dirname "$0")/../common/shell_harness.sh"
S=(run --scene sauce --scale 4 --quiet --threads 2)
"$bin" "${S[@]}" --solver pn-pcg --frames 7 --checkpoint-at 1,4,6 --out "$tmp/ref"
check "the run writing the checkpoints: exit 0" test $? -eq 0
"$bin" "${S[@]}" --solver pn-pcg --sample-from "$tmp/ref/checkpoints" --sample-frames 1,4,6 --out "$tmp/same"
check "sampled run, same solver: exit 0" test $? -eq 0
python3 - "$tmp/ref" "$tmp/same" >"$tmp/cmp" 2>&1 <<'PY'
import csv, sys
ref, part = sys.argv[1], sys.argv[2]
for name in ("steps.csv", "frames.csv"):
    f = [r for r in csv.DictReader(open(f"{ref}/{name}")) if int(r["frame"]) in (1, 4, 6)]
    p = list(csv.DictReader(open(f"{part}/{name}")))
    keys = [k for k in p[0] if not k.endswith("_s") and k != "threads"]
    assert len(f) == len(p) > 0, (name, len(f), len(p))
    for a, b in zip(f, p):
        d = [k for k in keys if a[k] != b[k]]
        assert not d, (name, a["frame"], d[:3], [a[k] for k in d[:3]], [b[k] for k in d[:3]])
print("ok")
PY
check "the sampled frames repeat the writing run's rows ($(tail -1 "$tmp/cmp"))" grep -qx ok "$tmp/cmp"
"$bin" "${S[@]}" --solver hot --sample-from "$tmp/ref/checkpoints" --sample-frames 1,4,6 --out "$tmp/hot"
check "sampled run, another solver: exit 0" test $? -eq 0
frames=$(python3 -c "import csv,sys; print(' '.join(r['frame'] for r in csv.DictReader(open(sys.argv[1]))))" "$tmp/hot/frames.csv")
check "one frames.csv row per sampled frame ($frames)" test "$frames" = "1 4 6"
sample=$(python3 -c "import json,sys; c=json.load(open(sys.argv[1]))['checkpoints']; print(c['sample_frames'], c['first_frame'])" "$tmp/hot/run.json")
check "run.json records the sample ($sample)" test "$sample" = "1,4,6 1"

C="$tmp/ref/checkpoints"
expect_input_error "^mpmbench: error: --sample-frames: needs --sample-from$" "${S[@]}" --solver hot --sample-frames 1
expect_input_error "^mpmbench: error: --sample-from: needs --sample-frames$" "${S[@]}" --solver hot --sample-from "$C"
expect_input_error "^mpmbench: error: --sample-frames '4,1': frame 1 after 4" "${S[@]}" --solver hot --sample-from "$C" --sample-frames 4,1
expect_input_error "^mpmbench: error: --sample-frames 2: .*frame_0002.ckpt" "${S[@]}" --solver hot --sample-from "$C" --sample-frames 1,2
expect_input_error "^mpmbench: error: --sample-frames: not with --frames" "${S[@]}" --solver hot --sample-from "$C" --sample-frames 1 --frames 3
expect_input_error "^mpmbench: error: --sample-frames: not with --from" "${S[@]}" --solver hot --sample-from "$C" --sample-frames 1 --from "$C/frame_0001.ckpt"
expect_input_error "^mpmbench: error: .*frame_0001.ckpt.*(scene|another)" run --scene sauce --scale 5 --quiet --solver hot --sample-from "$C" --sample-frames 1 --out "$tmp/bad"
check "no output folder for a refused sample" test ! -e "$tmp/bad"
finish
