#!/usr/bin/env bash
# A matrix reference with sample_frames (issue 28): the scene's reference
# run writes checkpoints at those frames (run --checkpoint-at) instead of a
# trajectory and runs first; every cell of the scene times each sampled
# frame alone from them (run --sample-from/--sample-frames): its frames.csv
# has exactly those frames, the writing solver's sampled rows repeat the
# reference run's, cells.csv gets a sample_frames column and the report
# says which frames were sampled; scripts/paper_scale_table.py computes
# HOT's speedups from the sampled frames, and a lower bound on them from a
# run the matrix excludes, stopped by its time limit (DIR/bounds/NAME/),
# refusing one that timed other states or was not stopped, and a study whose runs
# come from two machines (or whose timed runs come from two builds; a
# reference from another build is named, its ratio left out), joining parts from two machines a scene each (its
# --out replacing a table only with one made, scripts/fill_numbers.py quoting each part's numbers and dates apart);
# scripts/reproduce.sh remakes a study made in parts whole; other scenes run as before; a second
# `matrix run` has nothing to do; the sampled frames are part of the ids;
# a bad list, or first_timed_frame beside sample_frames, is a one-line
# error, exit 2.
. "$(dirname "$0")/../common/shell_harness.sh"
cat >"$tmp/m.json" <<'EOF2'
{"name": "sampled",
 "defaults": {"threads": 2, "scale": 5},
 "axes": {"scene": ["sauce", "bar3"], "solver": ["pn-pcg", "hot", "lbfgs-h"]},
 "scenes": {"sauce": {"reference": {"solver": "pn-pcg", "eps": 1e-7, "sample_frames": "1,4,6"}},
            "bar3": {"frames": 1}},
 "exclude": [{"scene": "sauce", "solver": "lbfgs-h"}]}
EOF2
"$bin" matrix run "$tmp/m.json" --out "$tmp/r" >"$tmp/run.txt" 2>&1
check "matrix run: exit 0" test $? -eq 0
check "the reference first, writing checkpoints" bash -c "sed -n 2p '$tmp/run.txt' | grep -q 'sauce/pn-pcg .*frames=7 checkpoints=1,4,6 (reference run): ok'"
ref=$(sed -n 2p "$tmp/run.txt" | sed 's/^\[[0-9]*\/[0-9]*\] //' | cut -d' ' -f1)
check "its checkpoints exist" test -f "$tmp/r/cells/$ref/checkpoints/frame_0004.ckpt"
check "two sampled cells name it" test "$(grep -c "sampled=1,4,6 reference=$ref: ok" "$tmp/run.txt")" -eq 2
python3 - "$tmp/r" "$ref" >"$tmp/cmp" 2>&1 <<'PY'
import csv, sys
root, ref = sys.argv[1], sys.argv[2]
cells = list(csv.DictReader(open(f"{root}/cells.csv")))
sampled = [c for c in cells if c["reference"] == ref]
assert len(sampled) == 2 and all(c["sample_frames"] == "1,4,6" for c in sampled), sampled
assert all(c["sample_frames"] == "" for c in cells if c["scene"] == "bar3"), "bar3 is not sampled"
for c in sampled:
    frames = [r["frame"] for r in csv.DictReader(open(f"{root}/cells/{c['id']}/frames.csv"))]
    assert frames == ["1", "4", "6"], (c["solver"], frames)
    assert c["timed_frames"] == "3", c["timed_frames"]
same = next(c for c in sampled if c["solver"] == "pn-pcg")
full = [r for r in csv.DictReader(open(f"{root}/cells/{ref}/steps.csv")) if r["frame"] in ("1", "4", "6")]
part = list(csv.DictReader(open(f"{root}/cells/{same['id']}/steps.csv")))
keys = [k for k in part[0] if not k.endswith("_s") and k != "threads"]
assert len(full) == len(part) > 0 and all(a[k] == b[k] for a, b in zip(full, part) for k in keys), "rows differ"
print("ok")
PY
check "sampled cells: the frames, the column, the writing solver's rows ($(tail -1 "$tmp/cmp"))" grep -qx ok "$tmp/cmp"
# sauce's pn-pcg reference and its timed pn-pcg cell share scene, solver and eps: two roles, not two repeats
reps=$(python3 "$src/scripts/study_status.py" --binary "$bin" --json "$tmp/r" 2>&1 |
  python3 -c 'import json,sys; print(json.load(sys.stdin)[0]["repeats"])' 2>&1)
check "study_status: a reference is not a repeat of its timed cell (repeats $reps)" test "$reps" = 1
python3 - "$tmp/r/matrix.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
m["description"] = "Each sampled cell times three frames of the animation."
json.dump(m, open(sys.argv[1], "w"))
PY
"$bin" matrix report "$tmp/r" >/dev/null 2>&1
check "the report names the sampled frames" grep -q "Sampled frames .*sauce: 1,4,6" "$tmp/r/report.md"
check "and finds a description of three frames true of the sampled cells (no 'Not as described')" \
  bash -c "grep -q 'times three frames' '$tmp/r/report.md' && ! grep -q 'Not as described' '$tmp/r/report.md'"

python3 "$src/scripts/paper_scale_table.py" "$tmp/r" >"$tmp/table0.md" 2>&1
check "the table before the bound: sauce waits for it, not for the matrix" \
  bash -c "grep -q 'Excluded from the matrix and not bounded yet: sauce/lbfgs-h (' '$tmp/table0.md' && ! grep -q '^| sauce | ' '$tmp/table0.md'"
# a bound: sauce/lbfgs-h is excluded from the matrix and run once from the same checkpoints, stopped
# by a time limit every step exceeds (so the outcome does not depend on the machine's speed)
bound="$tmp/r/bounds/sauce-lbfgs-h"
"$bin" run --scene sauce --solver lbfgs-h --scale 5 --threads 2 --sample-from "$tmp/r/cells/$ref/checkpoints" \
  --sample-frames 1,4,6 --max-run-seconds 1e-6 --quiet --out "$bound" >"$tmp/bound.txt" 2>&1
check "the bounded run stops at its limit (exit 0)" test $? -eq 0

# the paper-scale table (scripts/paper_scale_table.py) on the sampled study: HOT's speedup is the
# other solver's total over the sampled frames over HOT's, and the largest per-frame ratio, as the
# HOT paper's Table 1 defines them; the reference run's whole animation beside its sampled frames
python3 "$src/scripts/paper_scale_table.py" "$tmp/r" >"$tmp/table.md" 2>"$tmp/table.err"
rc=$?
check "paper_scale_table.py: exit 0 ($(head -c 200 "$tmp/table.err"))" test "$rc" -eq 0
python3 - "$tmp/r" "$tmp/table.md" "$src/scripts" >"$tmp/tcmp" 2>&1 <<'PY'
import csv, re, sys
sys.path.insert(0, sys.argv[3])
from matrix_report import fmt  # the table's number format
root, table = sys.argv[1], open(sys.argv[2]).read()
cells = [c for c in csv.DictReader(open(f"{root}/cells.csv")) if c["scene"] == "sauce"]
def frames(solver, role="cell"):
    c = next(c for c in cells if c["solver"] == solver and c["role"] == role)
    return {r["frame"]: float(r["wall_s"]) for r in csv.DictReader(open(f"{root}/cells/{c['id']}/frames.csv"))}
hot, pn = frames("hot"), frames("pn-pcg")
total = sum(pn.values()) / sum(hot.values())
per = max(pn[k] / hot[k] for k in hot)
row = f"| sauce | {int(cells[0]['particles']):,} | 1, 4, 6 | {fmt(total)}"
assert row in table, (row, [l for l in table.splitlines() if l.startswith("| sauce")])
assert f" / {fmt(per)} |" in table, per
whole = frames("pn-pcg", "reference")
ref = f"| sauce | pn-pcg | {len(whole)} | "
line = next((l for l in table.splitlines() if l.startswith(ref)), "")
# the whole animation's s/frame, marked busy when the machine was loaded (this test may share it)
assert re.search(rf"\| {re.escape(fmt(sum(whole.values()) / len(whole)))}( busy)? \|", line), (ref, line)
assert "| bar3 | pn-pcg |" not in table, "bar3 has no reference run"
print("ok")
PY
check "the table's speedups and reference row from the frames ($(tail -1 "$tmp/tcmp"))" grep -qx ok "$tmp/tcmp"

python3 - "$tmp/r" "$tmp/table.md" "$src/scripts" "$bound" >"$tmp/bcmp" 2>&1 <<'PY'
import csv, sys
sys.path.insert(0, sys.argv[3])
from matrix_report import fmt
root, table, bound = sys.argv[1], open(sys.argv[2]).read(), sys.argv[4]
cells = [c for c in csv.DictReader(open(f"{root}/cells.csv")) if c["scene"] == "sauce" and c["role"] == "cell"]
hot = next(c for c in cells if c["solver"] == "hot")
h = {r["frame"]: float(r["wall_s"]) for r in csv.DictReader(open(f"{root}/cells/{hot['id']}/frames.csv"))}
b = list(csv.DictReader(open(f"{bound}/frames.csv")))
assert b and b[-1]["complete"] == "0", b
total = sum(float(r["wall_s"]) for r in b) / sum(h.values())
per = max(float(r["wall_s"]) / h[r["frame"]] for r in b)
row = next((l for l in table.splitlines() if l.startswith("| sauce | ")), "")
assert row.rstrip(" |").split(" | ")[-1].startswith(f"≥ {fmt(total)} / ≥ {fmt(per)} (bound"), (total, per, row)
assert f"| sauce | lbfgs-h | stopped by its limit of {fmt(1e-6)} s in frame 1, step 1 of it" in table, "bounds table"
assert "Not run yet: " not in table or "sauce" not in table.split("Not run yet: ")[1].split("\n")[0], "sauce is done"
print("ok")
PY
check "the bound: at least its seconds over HOT's ($(tail -1 "$tmp/bcmp"))" grep -qx ok "$tmp/bcmp"
# a rerun of the study (scripts/reproduce.sh) runs its bounds again the same way, from its own checkpoints
cp -r "$tmp/r" "$tmp/r2" && rm -r "$tmp/r2/bounds"
python3 "$src/scripts/paper_scale_table.py" --rerun-bounds "$tmp/r" "$tmp/r2" "$bin" >"$tmp/rerun.txt" 2>&1
rc=$?
python3 - "$bound/run.json" "$tmp/r2/bounds/sauce-lbfgs-h/run.json" "$tmp/r2/cells/$ref/checkpoints" >"$tmp/rcmp" 2>&1 <<'PY'
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
for k in ("scene", "solver", "eps", "scale", "threads", "overrides"):
    assert a[k] == b[k], (k, a[k], b[k])
assert a["limits"]["max_run_seconds"] == b["limits"]["max_run_seconds"] == 1e-6, (a["limits"], b["limits"])
assert a["checkpoints"]["sample_frames"] == b["checkpoints"]["sample_frames"] == "1,4,6"
assert b["checkpoints"]["sample_from"] == sys.argv[3], b["checkpoints"]["sample_from"]
print("ok")
PY
check "--rerun-bounds: exit $rc, the same run from the rerun's checkpoints ($(tail -1 "$tmp/rcmp"))" \
  bash -c "test $rc -eq 0 && grep -qx ok '$tmp/rcmp' && python3 '$src/scripts/paper_scale_table.py' '$tmp/r2' >/dev/null"
# a bound of other states, or one its limit did not stop, is refused: one line, exit 2
mv "$bound" "$tmp/bound.ok"
cp -r "$tmp/bound.ok" "$bound"
sed -i 's/"sample_frames": "1,4,6"/"sample_frames": "1,4"/' "$bound/run.json"
python3 "$src/scripts/paper_scale_table.py" "$tmp/r" >/dev/null 2>"$tmp/berr1"
rc=$?
check "a bound of other frames: exit 2, one line ($(head -c 200 "$tmp/berr1"))" \
  bash -c "test $rc -eq 2 && test \$(wc -l <'$tmp/berr1') -eq 1 && grep -q \"sauce-lbfgs-h/run.json: sample_frames '1,4', but the study's sauce cells ran with '1,4,6'\" '$tmp/berr1'"
# timings from two machines are not one study: a bound, or a cell, run on another CPU is refused
rm -r "$bound" && cp -r "$tmp/bound.ok" "$bound"
sed -i 's/"cpu_model": *"[^"]*"/"cpu_model": "Other CPU"/' "$bound/run.json"
python3 "$src/scripts/paper_scale_table.py" "$tmp/r" >/dev/null 2>"$tmp/berr3"
rc=$?
check "a bound from another machine: exit 2, one line ($(head -c 200 "$tmp/berr3"))" \
  bash -c "test $rc -eq 2 && test \$(wc -l <'$tmp/berr3') -eq 1 && grep -q \"sauce-lbfgs-h/run.json: cpu_model 'Other CPU', but the study's sauce cells ran with\" '$tmp/berr3'"
rm -r "$bound"
pn=$(python3 -c 'import csv, sys; print(next(r["id"] for r in csv.DictReader(open(sys.argv[1]))
  if (r["scene"], r["solver"], r["role"]) == ("sauce", "pn-pcg", "cell")))' "$tmp/r/cells.csv")
cp "$tmp/r/cells/$pn/run.json" "$tmp/pn-run.json"
other_cell() { # FIELD VALUE PATTERN: a timed cell whose run.json names another FIELD is refused
  sed -i "s/\"$1\": *\"[^\"]*\"/\"$1\": \"$2\"/" "$tmp/r/cells/$pn/run.json"
  python3 "$src/scripts/paper_scale_table.py" "$tmp/r" >/dev/null 2>"$tmp/merr"
  local rc=$?
  check "a cell with another $1: exit 2, one line ($(head -c 200 "$tmp/merr"))" \
    bash -c "test $rc -eq 2 && test \$(wc -l <'$tmp/merr') -eq 1 && grep -q '$3' '$tmp/merr'"
  cp "$tmp/pn-run.json" "$tmp/r/cells/$pn/run.json"
}
other_cell cpu_model "Other CPU" 'the cells ran on 2 machines (.*Other CPU.*): not one study'
other_cell git_commit 0000000000000000000000000000000000000001 'the cells ran on 2 builds (.*0000000001.*): not one study'
# the reference (its states and the whole-animation column only) may come from another build: the
# table names it and leaves out its sampled/whole ratio
cp "$tmp/r/cells/$ref/run.json" "$tmp/ref-run.json"
cp -r "$tmp/bound.ok" "$bound" # with its bound sauce is complete and in the table
sed -i 's/"git_commit": *"[^"]*"/"git_commit": "0000000000000000000000000000000000000001"/' "$tmp/r/cells/$ref/run.json"
python3 "$src/scripts/paper_scale_table.py" "$tmp/r" >"$tmp/refbuild.md" 2>&1
rc=$?
check "a reference from another build: exit $rc, named, its ratio left out ($(grep -m1 '^| sauce | pn-pcg | 7' "$tmp/refbuild.md"))" \
  bash -c "test $rc -eq 0 && grep -q '^| sauce | pn-pcg | 7 | .* | - (reference: build 0000000) |' '$tmp/refbuild.md' &&
    grep -q \"^sauce's reference ran on build 0000000, its cells on \" '$tmp/refbuild.md'"
cp "$tmp/ref-run.json" "$tmp/r/cells/$ref/run.json"
rm -r "$bound"
"$bin" run --scene sauce --solver lbfgs-h --scale 5 --threads 2 --sample-from "$tmp/r/cells/$ref/checkpoints" \
  --sample-frames 1,4,6 --quiet --out "$bound" >"$tmp/whole.txt" 2>&1
python3 "$src/scripts/paper_scale_table.py" "$tmp/r" >/dev/null 2>"$tmp/berr2"
rc=$?
check "a bound its limit did not stop: exit 2 ($(head -c 200 "$tmp/berr2"))" \
  bash -c "test $rc -eq 2 && grep -q 'frames.csv: the run was not stopped by --max-run-seconds' '$tmp/berr2'"
rm -r "$bound"
"$bin" matrix run "$tmp/m.json" --out "$tmp/r" >"$tmp/again.txt" 2>&1
check "resume: nothing left" grep -q "0 to run" "$tmp/again.txt"

sed 's/"1,4,6"/"1,5"/' "$tmp/m.json" >"$tmp/m2.json"
"$bin" matrix run "$tmp/m.json" --out "$tmp/d1" --dry-run >"$tmp/dry1.txt"
"$bin" matrix run "$tmp/m2.json" --out "$tmp/d2" --dry-run >"$tmp/dry2.txt"
sauce_ids() { awk '$3 ~ /^sauce\// {print $1}' "$1" | sort; }
bar3_ids() { awk '$3 ~ /^bar3\// {print $1}' "$1" | sort; }
check "other sampled frames: every sauce id changes ($(sauce_ids "$tmp/dry2.txt" | wc -l) cells)" \
  test -z "$(comm -12 <(sauce_ids "$tmp/dry1.txt") <(sauce_ids "$tmp/dry2.txt"))" -a "$(sauce_ids "$tmp/dry2.txt" | wc -l)" -eq 3
check "and no bar3 id" test "$(bar3_ids "$tmp/dry1.txt")" = "$(bar3_ids "$tmp/dry2.txt")"

# a table of two parts, one machine each (here a copy of the study with its bound, split by scene,
# its second part relabelled as another CPU): each scene's row names its machine, each machine its
# own summary; a scene in both parts is refused
python3 - "$tmp/r" "$tmp/pa" "$tmp/pb" "$tmp/bound.ok" <<'PY'
import csv, glob, re, shutil, sys
src, pa, pb, bound = sys.argv[1:]
for d, drop in ((pa, "bar3"), (pb, "sauce")):
    shutil.copytree(src, d)
    if drop == "bar3":
        shutil.copytree(bound, f"{d}/bounds/sauce-lbfgs-h")
    rows = list(csv.DictReader(open(f"{d}/cells.csv")))
    with open(f"{d}/cells.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(r for r in rows if r["scene"] != drop)
for run in glob.glob(f"{pb}/cells/*/run.json"):
    text = open(run).read()
    open(run, "w").write(re.sub(r'"cpu_model": *"[^"]*"', '"cpu_model": "Other CPU"', text))
PY
python3 "$src/scripts/paper_scale_table.py" "$tmp/pa" "$tmp/pb" >"$tmp/parts.md" 2>"$tmp/parts.err"
rc=$?
check "a table of two parts: exit $rc ($(head -c 200 "$tmp/parts.err")), a machine a row and a summary a machine" \
  bash -c "test $rc -eq 0 && grep -q '^| sauce | [^|]* | [0-9,]* | 1, 4, 6 | ' '$tmp/parts.md' && ! grep -q '^| sauce | Other CPU |' '$tmp/parts.md' \
    && grep -q '^| bar3 | Other CPU | ' '$tmp/parts.md' && grep -q '^On Other CPU ($tmp/pb):' '$tmp/parts.md' \
    && test \$(grep -c '^On ' '$tmp/parts.md') -eq 2"
python3 "$src/scripts/paper_scale_table.py" "$tmp/pa" "$tmp/r" >/dev/null 2>"$tmp/parts2.err"
rc=$?
check "a scene in two parts: exit 2 ($(head -c 200 "$tmp/parts2.err"))" \
  bash -c "test $rc -eq 2 && grep -q \"$tmp/r: scene 'sauce' is also in $tmp/pa: a scene's runs come from one machine\" '$tmp/parts2.err'"
# --out (scripts/reproduce.sh's way to remake table.md) writes the table made, and leaves the old file
# when the parts cannot form one
python3 "$src/scripts/paper_scale_table.py" --out "$tmp/out.md" "$tmp/pa" "$tmp/pb" 2>"$tmp/out.err"
rc=$?
check "--out: exit $rc, the same table as on stdout ($(head -c 200 "$tmp/out.err"))" \
  bash -c "test $rc -eq 0 && cmp -s '$tmp/out.md' '$tmp/parts.md'"
python3 "$src/scripts/paper_scale_table.py" --out "$tmp/out.md" "$tmp/pa" "$tmp/r" 2>"$tmp/out2.err"
rc=$?
check "--out with parts that cannot join: exit $rc, the old table kept, no .part left ($(head -c 200 "$tmp/out2.err"))" \
  bash -c "test $rc -eq 2 && cmp -s '$tmp/out.md' '$tmp/parts.md' && test ! -e '$tmp/out.md.part'"

# the numbers the pages quote from such a table (scripts/fill_numbers.py's paper.<part>.* keys) are
# each part's own: its scenes, its dates, and HOT's lead over pn-pcg as that part's summary line gives it (the
# parts' cells marked quiet here, so that a lead is claimed whatever the load of the machine testing,
# and one run of the first moved to an earlier day)
python3 - "$tmp/pa" "$tmp/pb" <<'PY'
import csv, sys
for d in sys.argv[1:]:
    rows = list(csv.DictReader(open(f"{d}/cells.csv")))
    with open(f"{d}/cells.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(dict(r, machine_busy="0") for r in rows)
# one run of the first part started on an earlier day, so that its dates are a span
import json
run = f"{sys.argv[1]}/cells/{list(csv.DictReader(open(f'{sys.argv[1]}/cells.csv')))[0]['id']}/run.json"
j = json.load(open(run))
j["provenance"]["start_time"] = "2026-01-02T03:04:05Z"
json.dump(j, open(run, "w"))
PY
python3 "$src/scripts/paper_scale_table.py" "$tmp/pa" "$tmp/pb" >"$tmp/quiet.md" 2>&1
python3 - "$tmp" "$src/scripts" "$tmp/quiet.md" >"$tmp/keys.txt" 2>&1 <<'PY'
import re, sys
tmp, scripts, table = sys.argv[1:]
sys.path.insert(0, scripts)
import fill_numbers as f
f.RESULTS, f.PAPER_PARTS = tmp, {"epyc": "pa", "xeon": "pb"}
text = open(table).read()
for tag, part, scene in (("epyc", "pa", "sauce"), ("xeon", "pb", "bar3")):
    assert f.value(f"paper.{tag}.scenes")[0] == scene, (tag, f.value(f"paper.{tag}.scenes"))
    section = text.split(f"({tmp}/{part}):")[1].split("\nOn ")[0]
    printed = float(re.search(r"HOT against pn-pcg: ([0-9.]+)x", section).group(1))
    quoted = float(f.value(f"paper.{tag}.pn-pcg_geomean")[0])
    assert abs(quoted - printed) <= 0.01 * printed, (tag, quoted, printed)
    assert f.value(f"paper.{tag}.pn-pcg_n")[0] == "1", f.value(f"paper.{tag}.pn-pcg_n")
    # its dates: the first to the last day its runs started, read from the runs' own records
    import csv, json
    days = sorted({json.load(open(f"{tmp}/{part}/cells/{r['id']}/run.json"))["provenance"]["start_time"][:10]
                   for r in csv.DictReader(open(f"{tmp}/{part}/cells.csv"))})
    want = days[0] if days[0] == days[-1] else f"{days[0]} to {days[-1]}"
    assert tag != "epyc" or days[0] == "2026-01-02", days
    assert f.value(f"paper.{tag}.date")[0] == want, (tag, f.value(f"paper.{tag}.date"), want)
print("ok")
PY
check "per-part keys: each part's scenes and its own lead over pn-pcg ($(tail -1 "$tmp/keys.txt"))" \
  grep -qx ok "$tmp/keys.txt"

# scripts/reproduce.sh remakes a study made part by part (every invocation with --only) whole: the
# committed cells' scenes and solvers, a scene with every solver as scene/*, the globs reaching
# mpmbench unquoted; and everything when one invocation ran every cell
cp -r "$tmp/r" "$tmp/parts"
python3 - "$tmp/parts/provenance.json" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))
inv = p["invocations"][0]
p["invocations"] = [dict(inv, options=dict(inv["options"], only=o)) for o in (["sauce/*"], ["bar3/*"], ["1234abcd"])]
json.dump(p, open(sys.argv[1], "w"))
PY
MPMBENCH=$bin bash "$src/scripts/reproduce.sh" "$tmp/parts" --dry-run >"$tmp/repro.txt" 2>&1
rc=$?
cmd=$(grep "matrix run" "$tmp/repro.txt" | sed 's/^reproduce.sh: //')
check "reproduce.sh --dry-run on a study made in parts: exit $rc, the committed pairs ($cmd)" \
  bash -c "test $rc -eq 0 && grep -qF -- '--only sauce/pn-pcg --only sauce/hot --only bar3/\\* --out $tmp/parts.new' '$tmp/repro.txt'"
eval "$cmd --dry-run" >"$tmp/repro-dry.txt" 2>&1
check "its command lists the committed cells, no more ($(head -1 "$tmp/repro-dry.txt"))" \
  test "$(grep -c '  todo  ' "$tmp/repro-dry.txt")" -eq "$(($(wc -l <"$tmp/r/cells.csv") - 1))"
python3 - "$tmp/parts/provenance.json" <<'PY'
import json, sys
p = json.load(open(sys.argv[1]))
p["invocations"][1]["options"]["only"] = []
json.dump(p, open(sys.argv[1], "w"))
PY
MPMBENCH=$bin bash "$src/scripts/reproduce.sh" "$tmp/parts" --dry-run >"$tmp/repro2.txt" 2>&1
check "and the whole matrix after an invocation without --only" \
  bash -c "grep -q 'matrix run $tmp/m.json --out $tmp/parts.new' '$tmp/repro2.txt' && ! grep -q -- '--only' '$tmp/repro2.txt'"

sed 's/"1,4,6"/"4,1"/' "$tmp/m.json" >"$tmp/bad.json"
expect_input_error "^mpmbench: error: .*bad.json: scenes.sauce.reference.sample_frames: --sample-frames '4,1': frame 1 after 4" matrix run "$tmp/bad.json" --out "$tmp/b" --dry-run
sed 's/"scale": 5}/"scale": 5, "first_timed_frame": 1}/' "$tmp/m.json" >"$tmp/first.json"
expect_input_error "^mpmbench: error: .*first.json: scenes.sauce.reference.sample_frames: not with first_timed_frame 1" matrix run "$tmp/first.json" --out "$tmp/f" --dry-run
finish
