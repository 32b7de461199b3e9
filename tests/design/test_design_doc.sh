#!/usr/bin/env bash
# docs/design.md says what the code is, and the code agrees, for everything a
# test can check:
#  - every folder of the layout exists, and every source folder that exists is
#    named in the layout;
#  - the floors table names every floor target CMakeLists.txt builds, and
#    only those;
#  - every registered part (outer methods, inverse approximations, line
#    searches, stopping rules: `mpmbench list solvers`) and every adapter of
#    adapters/adapter_list.h is named, and every part the "one idea" table
#    names is registered or is an adapter;
#  - its claims about the code: the clock is read in core/event_log.c only;
#    only main exits (and a forked child that could not exec); a solver file
#    that reads particles or the grid belongs to an inverse approximation
#    declaring INV_NEEDS_PROBLEM; no file outside adapters/ includes an
#    adapter's header but the registry's list (scripts/check_includes.py
#    checks the rest of the floors, tests/design/test_floors.sh).
. "$(dirname "$0")/../common/shell_harness.sh"
"$bin" list solvers >"$tmp/parts" 2>&1
python3 - "$src" "$tmp/parts" >"$tmp/out" 2>&1 <<'PY'
import os, re, subprocess, sys
root, parts_file = sys.argv[1], sys.argv[2]
doc = open(os.path.join(root, "docs", "design.md")).read()
bad = []

# --- the layout -------------------------------------------------------------
layout = re.search(r"## Layout\n.*?```\n(.*?)```", doc, re.S)
if not layout:
    bad.append("design.md: no ```-block under '## Layout'")
    layout_text = ""
else:
    layout_text = layout.group(1)
entries = {}  # folder -> its paragraph in the layout block
current = None
for line in layout_text.splitlines():
    m = re.match(r"^([a-z_]+(?:/[a-z_]+)*/)\s", line)
    if m:
        current = m.group(1)
        entries[current] = line[len(current):]
    elif current:
        entries[current] += " " + line.strip()
for folder in entries:
    if not os.path.isdir(os.path.join(root, folder)):
        bad.append(f"layout names {folder}, which does not exist")
tracked = subprocess.run(["git", "-C", root, "ls-files"], capture_output=True, text=True).stdout.split()
source_dirs = set()
for f in tracked:
    d = os.path.dirname(f)
    top = d.split("/")[0] if d else ""
    if top in ("core", "solvers", "adapters", "experiments") and f.endswith((".c", ".h", ".inc", ".json")):
        source_dirs.add(d + "/")
    elif d and "/" not in d and not d.startswith("."):
        source_dirs.add(d + "/")  # every top-level folder
for d in sorted(source_dirs):
    if d in entries:
        continue
    parent = "/".join(d.rstrip("/").split("/")[:-1]) + "/"
    name = d.rstrip("/").split("/")[-1] + "/"
    if parent in entries and re.search(r"(?<![a-z_])" + re.escape(name), entries[parent]):
        continue
    bad.append(f"folder {d} is not in design.md's layout")

# --- the floors table -------------------------------------------------------
floors = []  # the target column of the floors table: | floor | `target` ... | may use |
for line in re.search(r"\| floor \| target \| may use \|\n(.*?)\n\n", doc, re.S).group(1).splitlines()[1:]:
    m = re.match(r"`(mpm_[a-z_]+|mpmbench)`", line.split("|")[2].strip())
    if m:
        floors.append(m.group(1))
cmake = open(os.path.join(root, "CMakeLists.txt")).read()
built = set(re.findall(r"mpm_floor\((mpm_[a-z_]+)", cmake))
if not floors:
    bad.append("design.md: no floors table (| `folder/` | `target` | ...)")
for t in floors:
    if t != "mpmbench" and t not in built and not t.startswith("mpm_adapter"):
        bad.append(f"floors table names {t}, which CMakeLists.txt does not build")
for t in sorted(built):
    if t not in floors and not t.startswith("mpm_adapter_"):
        bad.append(f"CMakeLists.txt builds the floor {t}, which the floors table does not name")

# --- the parts ----------------------------------------------------------------
listing = open(parts_file).read()
section = None
registered = set()
for line in listing.splitlines():
    head = re.match(r"^(outer methods|inverse approximations|line searches|stopping rules)", line)
    if head:
        section = head.group(1)
        continue
    if not line.strip():
        section = None
        continue
    if section and line.startswith("  "):
        registered.add(line.split()[0])
adapters = re.findall(r"^\s*X\(([a-z0-9_]+),", open(os.path.join(root, "adapters", "adapter_list.h")).read(), re.M)
if not registered:
    bad.append("`mpmbench list solvers` listed no parts")
for p in sorted(registered | set(adapters)):
    if f"`{p}`" not in doc:
        bad.append(f"the part {p} is not named in design.md (as `{p}`)")
table = re.search(r"\| outer method \| inverse approximation \|.*?\n\n", doc, re.S)
for row in (table.group(0).splitlines()[2:] if table else []):
    for name in re.findall(r"`([a-z0-9-]+)`", row):
        if name not in registered and name not in adapters:
            bad.append(f"the 'one idea' table names {name}, which is neither registered nor an adapter")

# --- claims about the code ------------------------------------------------------
def sources(*tops):
    for f in tracked:
        if f.split("/")[0] in tops and f.endswith((".c", ".h", ".inc")):
            yield f, open(os.path.join(root, f), errors="replace").read()

for f, text in sources("core", "solvers", "adapters", "experiments"):
    code = re.sub(r"/\*.*?\*/|//[^\n]*", "", text, flags=re.S)
    if f != "core/event_log.c" and re.search(r"\b(omp_get_wtime|clock_gettime|gettimeofday)\s*\(", code):
        bad.append(f"{f} reads a clock (design.md: only core/event_log.c does)")
    if f != "experiments/commands/main.c":
        for m in re.finditer(r"(?<![_a-z])(exit|abort|MPI_Abort|quick_exit)\s*\(", code):
            bad.append(f"{f} calls {m.group(1)}() (design.md: only main exits)")
    if f.startswith("solvers/") and re.search(r'#include "core/(grid|transfer|particles|step)\.h"', text):
        folder = os.path.dirname(f)
        declares = any("INV_NEEDS_PROBLEM" in t for g, t in sources("solvers") if os.path.dirname(g) == folder)
        if not declares:
            bad.append(f"{f} reads particles or the grid but no inverse approximation of {folder}/ "
                       f"declares INV_NEEDS_PROBLEM")
for b in bad:
    print(b)
print(f"{len(entries)} layout folders, {len(floors)} floors, {len(registered)} parts and {len(adapters)} adapters; "
      f"{len(bad)} problems")
sys.exit(1 if bad else 0)
PY
rc=$?
checks=$((checks + 1))
if [ $rc -ne 0 ]; then echo "FAIL: docs/design.md against the code"; cat "$tmp/out"; fails=$((fails + 1)); fi
finish
