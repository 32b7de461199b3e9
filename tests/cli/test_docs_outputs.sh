#!/usr/bin/env bash
# docs/outputs.md documents every output column: this test runs the program
# (a run with every optional file, one run per registered inverse
# approximation, a matrix with every optional cells.csv column, --check and
# the report) and checks, file by file, that the columns written are exactly
# the ones documented (named axes aside), the inverse_stats.csv keys of each
# inverse approximation too, and run.json's fields.
. "$(dirname "$0")/../common/shell_harness.sh"
doc="$src/docs/outputs.md"
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2} OMP_WAIT_POLICY=passive

run() { "$bin" run --scene bar3 --scale 6 --frames 1 --quiet "$@" >>"$tmp/log" 2>&1; }
check "run with every optional file" run --solver hot --history --error-ref pn-pcg:1e-9 --trajectory \
  --particles "$tmp/ply" --out "$tmp/full"

# every registered inverse approximation, composed with pn
invs=$("$bin" list solvers | awk '/^inverse approximations:/{on=1; next} /^$/{on=0} on{print $1}')
check "list solvers names inverse approximations" test -n "$invs"
for inv in $invs; do
  check "run pn:$inv" run --solver "pn:$inv" --out "$tmp/inv-$inv"
done

cat >"$tmp/m.json" <<'JSON'
{"name": "docs-outputs",
 "defaults": {"scene": "drop", "frames": 1, "threads": 1, "ranks": 1, "scale": 2},
 "axes": {"scene": ["drop", "stretched-box"], "solver": ["hot"], "error_ref": ["pn-pcg:1e-9"],
          "sets": {"stiff": [{"materials.soft.E": 1e5}]}},
 "scenes": {"stretched-box": {"scale": 4, "reference": {"solver": "pn-pcg", "eps": 1e-7, "sample_frames": "0"}}},
 "reference": {"solver": "pn-pcg", "eps": 1e-9},
 "baseline": "hot", "repeat": 2}
JSON
check "matrix run --check" "$bin" matrix run "$tmp/m.json" --out "$tmp/m" --check >>"$tmp/log" 2>&1
check "matrix report" "$bin" matrix report "$tmp/m" >>"$tmp/log" 2>&1

python3 - "$doc" "$tmp" $invs <<'PY' >"$tmp/compare" 2>&1
import csv, json, os, re, sys
doc, tmp, invs = sys.argv[1], sys.argv[2], sys.argv[3:]
text = open(doc).read()
sections = {}
for m in re.finditer(r"^### `([^`]+)`\n(.*?)(?=^#{2,3} |\Z)", text, re.S | re.M):
    sections[m.group(1)] = m.group(2)

def first_table(body):
    """The backticked first cells of the section's first table."""
    cols, started = [], False
    for line in body.splitlines():
        if line.startswith("|"):
            started = True
            c = line.split("|")[1].strip()
            if c.startswith("`") and c.endswith("`"):
                cols.append(c.strip("`"))
        elif started:
            break
    return cols

def header(path):
    with open(path, newline="") as f:
        return next(csv.reader(f))

bad = []
def compare(name, written, allowed_extra=()):
    documented = first_table(sections.get(name, ""))
    if not documented:
        bad.append(f"{name}: no section with a column table in docs/outputs.md")
        return
    for c in written:
        if c not in documented and c not in allowed_extra:
            bad.append(f"{name}: column '{c}' is written but not documented")
    for c in documented:
        if c not in written:
            bad.append(f"{name}: column '{c}' is documented but not written")

full = os.path.join(tmp, "full")
for f in ["steps.csv", "frames.csv", "iters.csv", "inverse_stats.csv"]:
    compare(f, header(os.path.join(full, f)))
compare("mg_levels.csv", header(os.path.join(full, "mg_levels.csv")))
m = os.path.join(tmp, "m")
compare("cells.csv", header(os.path.join(m, "cells.csv")), allowed_extra=("stiff",))
compare("check.csv", header(os.path.join(m, "check.csv")), allowed_extra=("stiff",))
for f in ["report.csv", "profile.csv", "wp.csv", "profile_accuracy.csv"]:
    p = os.path.join(m, f)
    if os.path.exists(p):
        compare(f, header(p))
    else:
        bad.append(f"{f}: the report did not write it")

# inverse_stats.csv keys per inverse approximation
keys_doc = {}
for line in sections.get("inverse_stats.csv", "").splitlines():
    cells = [c.strip() for c in line.split("|")[1:-1]]
    if len(cells) == 3 and cells[1].startswith("`") and cells[0].startswith("`"):
        for inv in re.findall(r"`([^`]+)`", cells[0]):
            keys_doc.setdefault(inv, set()).add(cells[1].strip("`"))
for inv in invs:
    with open(os.path.join(tmp, f"inv-{inv}", "inverse_stats.csv"), newline="") as f:
        written = {r["key"] for r in csv.DictReader(f)}
    if written != keys_doc.get(inv, set()):
        bad.append(f"inverse_stats.csv keys of {inv}: written {sorted(written)}, documented "
                   f"{sorted(keys_doc.get(inv, set()))}")

# run.json: every top-level field a row, every nested field named in its row
rows = {}
for line in sections.get("run.json", "").splitlines():
    cells = [c.strip() for c in line.split("|")[1:-1]]
    if len(cells) == 2 and cells[0].startswith("`"):
        rows[cells[0].strip("`")] = cells[1]
rj = json.load(open(os.path.join(full, "run.json")))
for k, v in rj.items():
    if k not in rows:
        bad.append(f"run.json: field '{k}' is written but not documented")
        continue
    if isinstance(v, dict) and k not in ("solver_options", "overrides"):
        subs = set(v)
        for s in v.values():
            if isinstance(s, dict) and k != "accuracy":
                subs |= set(s)
        for s in subs:
            if f"`{s}`" not in rows[k]:
                bad.append(f"run.json: {k}.{s} is written but not named in the '{k}' row")
# a field only some inverse approximations write (inverse_view) is written by one of their runs
written = set(rj)
for inv in invs:
    path = os.path.join(tmp, f"inv-{inv}", "run.json")
    if os.path.exists(path):
        written |= set(json.load(open(path)))
# inverse_view comes from the petsc adapter alone: a build without it writes none
if "petsc" not in invs:
    written.add("inverse_view")
for k in rows:
    if k not in written:
        bad.append(f"run.json: field '{k}' is documented but not written")
for b in bad:
    print(b)
print(f"{len(bad)} differences")
sys.exit(1 if bad else 0)
PY
rc=$?
checks=$((checks + 1))
if [ $rc -ne 0 ]; then echo "FAIL: docs/outputs.md and the program's outputs differ:"; cat "$tmp/compare"; fails=$((fails + 1)); fi
[ "$fails" -gt 0 ] && tail -20 "$tmp/log"
finish
