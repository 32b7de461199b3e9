/* `mpmbench bench`: throughput of the kernels on a scene's first-step state,
 * in one process, set against the machine's limits measured in the same
 * process (experiments/bench/machine_limits.h: DRAM STREAM triad, FMA peak):
 *   spmv      block-CSR SpMV (GB/s of matrix + vector traffic) against a
 *             triad over the same working-set size, and H x for comparison;
 *   hessvec   matrix-free H x;
 *   assemble  projected dP/dF and the block-CSR assembly (and scatter only);
 *   energy    one line-search trial: F(dv), SVD, psi and P per particle;
 *   gradient  the gradient at that point (the scatter of the cached P);
 *   p2g, g2p  the MLS-MPM supplement's transfer kernels (section 3: P2G with
 *             the force from F, linear elasticity, and the normalisation;
 *             G2P with the F update and advection), APIC or MLS by the
 *             scene's "transfer" (--transfer apic|mls|pic_flip; PIC/FLIP's
 *             P2G is APIC's);
 *   all       every one.
 * Each kernel line gives particles/s, the model's minimum bytes and flops
 * per particle, GB/s and GFLOP/s, their fractions of STREAM and of the peak,
 * and the spread (median over best of the repetitions). */
#ifndef MPM_BENCH_H
#define MPM_BENCH_H

#include "experiments/run/run.h"

int bench_run(const char *what, const RunConfig *cfg);

#endif
