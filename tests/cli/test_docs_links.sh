#!/usr/bin/env bash
# Every relative link and image in README.md, results/README.md and docs/*.md
# points at a file or folder of the repository (anchors and web addresses
# aside), and no page points outside the repository (the workplace's shared folder or a machine path).
. "$(dirname "$0")/../common/shell_harness.sh"
python3 - "$src" >"$tmp/out" 2>&1 <<'PY'
import glob, os, re, sys
root = os.path.abspath(sys.argv[1])
pages = [os.path.join(root, "README.md"), os.path.join(root, "results", "README.md")]
pages += sorted(glob.glob(os.path.join(root, "docs", "*.md")))
bad = 0
for page in pages:
    text = open(page).read()
    for m in re.finditer(r"\]\(([^)\s]+)\)", text):
        target = m.group(1).split("#")[0]
        if not target or re.match(r"^[a-z]+:", target):
            continue
        path = os.path.normpath(os.path.join(os.path.dirname(page), target))
        if not path.startswith(os.path.normpath(root)) or not os.path.exists(path):
            print(f"{os.path.relpath(page, root)}: broken link {m.group(1)}")
            bad += 1
    for m in re.finditer(r"\.\./[s]hared|/[w]ork/", text):
        print(f"{os.path.relpath(page, root)}: points outside the repository: {m.group(0)}")
        bad += 1
print(f"{len(pages)} pages, {bad} problems")
sys.exit(1 if bad else 0)
PY
rc=$?
checks=$((checks + 1))
if [ $rc -ne 0 ]; then echo "FAIL: documentation links"; cat "$tmp/out"; fails=$((fails + 1)); fi
finish
