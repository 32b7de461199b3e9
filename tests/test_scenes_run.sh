#!/usr/bin/env bash
# Every scene of the suite runs at a coarse scale (~4k particles; one frame,
# more for Boards and Sauce whose action starts later) with HOT: exit 0 (no
# NaN, no particle leaving the domain) and every step converged to the CN
# tolerance (scripts/smoke_matrix.sh does the work). With the original meshes
# beside the source tree (../shared/data/meshes; optional) the mesh variants
# run too.
meshes="$2/../shared/data/meshes"
if [ -d "$meshes" ]; then
  exec bash "$2/scripts/smoke_matrix.sh" --bin "$1" --solvers hot --asset-dir "$meshes"
fi
echo "original meshes not found at $meshes: mesh variants skipped"
exec bash "$2/scripts/smoke_matrix.sh" --bin "$1" --solvers hot
