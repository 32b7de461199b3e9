/* `mpmbench bench`: throughput of the kernels on a scene's first-step state,
 * in one process: block-CSR SpMV (GB/s of matrix + vector traffic) against a
 * STREAM triad over the same working-set size, Hessian assembly and P2G
 * (particles/s), and the matrix-free product for comparison. */
#ifndef MPM_BENCH_H
#define MPM_BENCH_H

#include "experiments/run/run.h"

int bench_run(const char *what, const RunConfig *cfg);

#endif
