#!/usr/bin/env bash
# `mpmbench decompose` (experiments/dist/decompose_cmd.c): the table's rows
# add up (every particle and node owned once, a rank's local grid = its
# owned nodes that its particles reach + its ghosts), one rank has no halo,
# the cut balances particles, a checkpoint's later state is counted with
# --from (sauce fills up from a source, and has no particle at frame 0), and bad --ranks values, more
# ranks than blocks and a bad checkpoint are one-line errors, exit 2.
. "$(dirname "$0")/../common/shell_harness.sh"

"$bin" decompose --scene bar3 --scale 2 --ranks 1,2,3,5 --threads 2 --out "$tmp/bar3.csv"
check "bar3: exit 0" test $? -eq 0
python3 - "$tmp/bar3.csv" >"$tmp/sums.txt" 2>&1 <<'PY'
import csv, sys
from collections import defaultdict
rows = list(csv.DictReader(open(sys.argv[1])))
by = defaultdict(list)
for r in rows:
    by[int(r["ranks"])].append(r)
assert sorted(by) == [1, 2, 3, 5], sorted(by)
n, nodes = int(rows[0]["particles"]), int(rows[0]["nodes"])
for R, rs in by.items():
    I = lambda k: [int(r[k]) for r in rs]
    assert [int(r["rank"]) for r in rs] == list(range(R)), (R, "ranks in order")
    assert sum(I("owned_particles")) == n, (R, "particles", sum(I("owned_particles")), n)
    assert sum(I("owned_nodes")) == nodes, (R, "nodes", sum(I("owned_nodes")), nodes)
    for r in rs:
        local = int(r["owned_nodes"]) - int(r["owned_untouched"]) + int(r["ghost_nodes"])
        assert int(r["touched_nodes"]) == local, (R, r["rank"], "touched", r["touched_nodes"], local)
    # each cut lies within half a block (at most 512 particles here) of its target
    assert max(I("owned_particles")) <= n / R + 512, (R, "imbalance", I("owned_particles"))
    if R == 1:
        assert I("ghost_nodes") == [0] and I("owned_untouched") == [0] and I("ghost_row_blocks") == [0], rs
    else:
        assert min(I("send_ranks")) >= 0 and sum(I("ghost_nodes")) > 0 and sum(I("send_ranks")) == sum(I("receive_ranks")), R
print("ok")
PY
check "bar3: the rows add up ($(tail -1 "$tmp/sums.txt"))" grep -qx ok "$tmp/sums.txt"

"$bin" run --scene sauce --scale 6 --solver pn-pcg --frames 3 --checkpoint-at 1,2 --threads 2 --quiet --out "$tmp/sauce"
check "sauce: checkpoint written" test -f "$tmp/sauce/checkpoints/frame_0002.ckpt"
"$bin" decompose --scene sauce --scale 6 --ranks 2 --from "$tmp/sauce/checkpoints/frame_0001.ckpt" --out "$tmp/s0.csv"
"$bin" decompose --scene sauce --scale 6 --ranks 2 --from "$tmp/sauce/checkpoints/frame_0002.ckpt" --out "$tmp/s2.csv"
check "sauce --from: exit 0" test $? -eq 0
p0=$(python3 -c "import csv,sys; r=next(csv.DictReader(open(sys.argv[1]))); print(r['frame'], r['particles'])" "$tmp/s0.csv")
p2=$(python3 -c "import csv,sys; r=next(csv.DictReader(open(sys.argv[1]))); print(r['frame'], r['particles'])" "$tmp/s2.csv")
check "sauce --from counts frames 1 and 2, more particles at 2 ($p0 / $p2)" \
  test "${p2%% *}" = 2 -a "${p2##* }" -gt "${p0##* }" -a "${p0%% *}" = 1

expect_input_error "^mpmbench: error: --ranks '0': expected" decompose --scene bar3 --scale 6 --ranks 0
expect_input_error "^mpmbench: error: --ranks '2,,4': expected" decompose --scene bar3 --scale 6 --ranks 2,,4
expect_input_error "^mpmbench: error: --ranks '2,': a comma at the end" decompose --scene bar3 --scale 6 --ranks 2,
expect_input_error "^mpmbench: error: --ranks 'x': expected" decompose --scene bar3 --scale 6 --ranks x
expect_input_error "^mpmbench: error: ranks: 4000 ranks but only [0-9]+ node blocks hold particles \(more ranks than blocks" \
  decompose --scene bar3 --scale 6 --ranks 4000
echo "not a checkpoint" >"$tmp/bad.ckpt"
expect_input_error "^mpmbench: error: .*bad.ckpt" decompose --scene bar3 --scale 6 --from "$tmp/bad.ckpt"
expect_input_error "^mpmbench: error: .*--solver" decompose --scene bar3 --solver hot
expect_input_error "^mpmbench: error: ranks: 2 ranks but no particle to own" decompose --scene sauce --scale 6 --ranks 2
finish
