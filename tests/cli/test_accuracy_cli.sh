#!/usr/bin/env bash
# needs: MPM_WITH_CHOLMOD
# The accuracy flags of `run` (issue 10, SPEC 11): --trajectory writes
# trajectory.bin in its documented format; --dt-from replays a run's dt
# sequence bit for bit; --trajectory-ref against the same run gives exactly
# zero, also with --error-ref on (the reference solve leaves the step
# untouched), and a positive, finite error for another solver; references
# of another scene, particle count, frame count or without a trajectory are
# refused with exit 2 naming both sides, before anything is written; the
# columns are empty without the flags and documented in run.json.
. "$(dirname "$0")/../common/shell_harness.sh"

col() { # csv column: every row's value
  python3 - "$@" <<'PY'
import csv, sys
for r in csv.DictReader(open(sys.argv[1])):
    print(r[sys.argv[2]])
PY
}
run=(run --scene bar3 --scale 5 --frames 2 --threads 2 --quiet)

"$bin" "${run[@]}" --solver pn-pcg --out "$tmp/a" --trajectory
check "reference run: exit 0" test $? -eq 0
check "the accuracy columns are empty without the flags" test "$(col "$tmp/a/steps.csv" err_h | sort -u)" = "" -a \
  "$(col "$tmp/a/frames.csv" pos_rms | sort -u)" = ""
check "max_energy_rise 0 at every step (halving never accepts a rise)" test "$(col "$tmp/a/steps.csv" max_energy_rise | sort -u)" = 0
python3 - "$tmp/a" >"$tmp/fmt.txt" 2>&1 <<'PY'
import csv, json, struct, sys
d = sys.argv[1]
data = open(f"{d}/trajectory.bin", "rb").read()
run = json.load(open(f"{d}/run.json"))
assert data[:8] == b"MPMTRAJ1", data[:8]
version, hbytes = struct.unpack("<II", data[8:16])
scene = data[16:80].rstrip(b"\0").decode()
dx, n0 = struct.unpack("<dQ", data[80:96])
assert (version, hbytes, scene, n0) == (1, 96, "bar3", run["particles"]), (version, hbytes, scene, n0)
assert abs(dx - run["dx"]) < 1e-15, dx
pos, frames = 96, []
while pos < len(data):
    frame, pad, t, n = struct.unpack("<IIdQ", data[pos:pos + 24])
    frames.append((frame, t, n))
    x = struct.unpack(f"<{3 * n}d", data[pos + 24:pos + 24 + 24 * n])
    assert all(1.5 <= x[3 * k + 0] <= 2.5 and 2.3 <= x[3 * k + 1] <= 4.2 for k in range(n)), "positions in the domain"
    pos += 24 + 48 * n
assert pos == len(data), "whole records"
steps = list(csv.DictReader(open(f"{d}/steps.csv")))
ends = [float(s["t"]) + float(s["dt"]) for s in steps]
assert [f for f, _, _ in frames] == [0, 1], frames
assert all(n == n0 for _, _, n in frames)
assert abs(frames[-1][1] - ends[-1]) < 1e-15 and abs(frames[-1][1] - 2 / 48) < 1e-12, (frames, ends[-1])
print("ok", len(frames), "frames of", n0)
PY
check "trajectory.bin: header, one record per frame, t at the frame end ($(tail -1 "$tmp/fmt.txt"))" grep -q "^ok 2 frames" "$tmp/fmt.txt"

"$bin" "${run[@]}" --solver pn-pcg --out "$tmp/self" --dt-from "$tmp/a" --trajectory-ref "$tmp/a"
check "self: exit 0" test $? -eq 0
check "self: the dt sequence replayed exactly" test "$(col "$tmp/self/steps.csv" dt)" = "$(col "$tmp/a/steps.csv" dt)"
check "self: t too" test "$(col "$tmp/self/steps.csv" t)" = "$(col "$tmp/a/steps.csv" t)"
for c in pos_rms pos_max vel_rms; do
  check "self: $c exactly 0 at every frame" test "$(col "$tmp/self/frames.csv" $c | sort -u)" = "0.000000000e+00"
done

"$bin" "${run[@]}" --solver pn-pcg --out "$tmp/self-ref" --dt-from "$tmp/a" --trajectory-ref "$tmp/a" --error-ref pn-cholmod
check "self with --error-ref: exit 0" test $? -eq 0
check "self with --error-ref: pos_rms still exactly 0 (the reference solve leaves the step as it was)" \
  test "$(col "$tmp/self-ref/frames.csv" pos_rms | sort -u)" = "0.000000000e+00"
check "self with --error-ref: every step measured" test "$(col "$tmp/self-ref/steps.csv" ref_solver | sort -u)" = pn-cholmod
check "self with --error-ref: err_h in (0, 1]" python3 -c "import sys; v=[float(x) for x in sys.argv[1:]]; sys.exit(not v or not all(0 < x <= 1 for x in v))" \
  $(col "$tmp/self-ref/steps.csv" err_h)
check "self with --error-ref: ref_s reported" python3 -c "import sys; sys.exit(not all(float(x) > 0 for x in sys.argv[1:]))" \
  $(col "$tmp/self-ref/steps.csv" ref_s)

"$bin" "${run[@]}" --solver hot --eps 1e-5 --out "$tmp/hot" --dt-from "$tmp/a" --trajectory-ref "$tmp/a" --error-ref auto
check "hot: exit 0" test $? -eq 0
check "hot: the reference's dt sequence" test "$(col "$tmp/hot/steps.csv" dt)" = "$(col "$tmp/a/steps.csv" dt)"
check "hot: pos_rms positive and finite, pos_max >= pos_rms" python3 - "$tmp/hot/frames.csv" <<'PY'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
ok = all(0 < float(r["pos_rms"]) <= float(r["pos_max"]) < 1 and 0 < float(r["vel_rms"]) < 1 for r in rows)
sys.exit(not (ok and len(rows) == 2))
PY
check "hot: auto takes pn-cholmod at this size" test "$(col "$tmp/hot/steps.csv" ref_solver | sort -u)" = pn-cholmod
check "run.json documents the columns" python3 -c "
import json, sys; a = json.load(open('$tmp/hot/run.json'))['accuracy']
sys.exit(not (a['dt_from'] and a['trajectory_ref'] and a['error_ref'].startswith('auto') and
              all(k in a['columns'] for k in ('err_h', 'e_gap', 'err_v_max', 'pos_rms', 'pos_max', 'vel_rms', 'ref_s'))))"

# refusals: exit 2, one line naming both sides, nothing written
"$bin" run --scene drop --scale 3 --frames 1 --quiet --solver pn-pcg --out "$tmp/noref"
expect_input_error "--trajectory-ref .*: the reference is scene \"bar3\", this run is scene \"drop\"" \
  run --scene drop --scale 3 --frames 1 --solver pn-pcg --out "$tmp/x1" --trajectory-ref "$tmp/a"
expect_input_error "--dt-from .*: the reference starts with [0-9]+ particles, this run with [0-9]+" \
  run --scene bar3 --scale 6 --frames 1 --solver pn-pcg --out "$tmp/x2" --dt-from "$tmp/a"
expect_input_error "--trajectory-ref .*: the reference starts with [0-9]+ particles, this run with [0-9]+" \
  run --scene bar3 --scale 6 --frames 1 --solver pn-pcg --out "$tmp/x3" --trajectory-ref "$tmp/a"
expect_input_error "--dt-from .*: the reference has 2 frames, this run asks for 3" \
  run --scene bar3 --scale 5 --frames 3 --solver pn-pcg --out "$tmp/x4" --dt-from "$tmp/a"
expect_input_error "--trajectory-ref .*: the reference has 2 frames, this run asks for 3" \
  run --scene bar3 --scale 5 --frames 3 --solver pn-pcg --out "$tmp/x5" --trajectory-ref "$tmp/a"
expect_input_error "--trajectory-ref .*noref.*run the reference with --trajectory" \
  run --scene drop --scale 3 --frames 1 --solver pn-pcg --out "$tmp/x6" --trajectory-ref "$tmp/noref"
expect_input_error "--dt-from '.*nowhere': not a run directory" \
  run --scene drop --scale 3 --frames 1 --solver pn-pcg --out "$tmp/x7" --dt-from "$tmp/nowhere"
expect_input_error "--error-ref pn-pgc: .*unknown solver" \
  run --scene drop --scale 3 --frames 1 --solver pn-pcg --out "$tmp/x8" --error-ref pn-pgc
check "nothing written by a refused run" bash -c "! ls -d '$tmp'/x? 2>/dev/null"
finish
