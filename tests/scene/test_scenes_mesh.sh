#!/usr/bin/env bash
# The scene variants with the original meshes (ArmaCat, Wheel, Sauce's
# turkey; experiments/matrices/smoke-meshes.json) run as test_scenes_run.sh
# runs the suite: HOT at the smoke scales, every cell ok with every step
# converged. The meshes are not part of the repository: their folder comes
# from the environment variable MPM_MESH_DIR (docs/scenes.md); without it,
# or without one of the files, the test is skipped (exit 77).
. "$(dirname "$0")/../common/shell_harness.sh"
. "$(dirname "$0")/../common/smoke_cells.sh"

[ -n "${MPM_MESH_DIR:-}" ] || skip "MPM_MESH_DIR (the original meshes' folder, docs/scenes.md) is not set"
for mesh in luckyCat20K.obj Armadillo.obj cylinder.obj wheel.obj turkey.obj; do
  [ -r "$MPM_MESH_DIR/$mesh" ] || skip "$MPM_MESH_DIR has no $mesh"
done
smoke "$src/experiments/matrices/smoke-meshes.json" 4 --asset-dir "$MPM_MESH_DIR"
finish
