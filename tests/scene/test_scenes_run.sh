#!/usr/bin/env bash
# Every scene of the suite runs at a coarse scale (~4k particles; one frame,
# more for Boards and Sauce whose action starts later) with HOT: the smoke
# matrix (experiments/matrices/smoke.json) restricted to hot, with APIC and
# with MLS-MPM (its transfer axis, SPEC 9), every cell
# ending ok (no NaN, no particle leaving the domain) with every step
# converged to the CN tolerance. The mesh variants are test_scenes_mesh.sh.
. "$(dirname "$0")/../common/shell_harness.sh"
. "$(dirname "$0")/../common/smoke_cells.sh"

smoke "$src/experiments/matrices/smoke.json" 32
finish
