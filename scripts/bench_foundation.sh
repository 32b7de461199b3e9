#!/usr/bin/env bash
# Issue-2 figures in one run: kernel throughput (bench all) on bar3 (middle
# E = 1e9) at ~50k particles, 2 threads, into results/foundation/bench.txt,
# and the foundation matrix (PN-PCG against PN-PCG(MF), 5 frames) with its
# report. A matrix cannot run `bench`; the rest is the matrix file
# experiments/matrices/foundation.json.
set -euo pipefail
cd "$(dirname "$0")/.."
bin="${MPMBENCH:-build-native/mpmbench}"
out=results/foundation
mkdir -p "$out"
"$bin" bench all --scene bar3 --scale 1.86 --set materials.middle.E=1e9 --threads 2 | tee "$out/bench.txt"
"$bin" matrix run experiments/matrices/foundation.json --out "$out"
"$bin" matrix report "$out"
