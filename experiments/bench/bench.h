/* `mpmbench bench`: throughput of the kernels on a scene's first-step state,
 * in one process, set against the machine's limits measured in the same
 * process (experiments/bench/machine_limits.h: DRAM STREAM triad, FMA peak):
 *   spmv      block-CSR SpMV (GB/s of matrix + vector traffic) against a
 *             triad over the same working-set size, and H x for comparison;
 *   hessvec   matrix-free H x;
 *   assemble  projected dP/dF and the block-CSR assembly (and scatter only);
 *   tangent   the projected dP/dF alone;
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

/* The kernels, in the order `bench all` runs them: X(NAME) for each. The one
 * list of them: the command's operands (bench_operands) and bench_run's
 * dispatch (bench_NAME in bench.c) are made from it, and NAME prefixes the
 * kernel's key=value lines. */
#define BENCH_KERNELS(X) X(spmv) X(hessvec) X(assemble) X(tangent) X(energy) X(gradient) X(p2g) X(g2p)

/* The operands `mpmbench bench` takes: every kernel's name, then "all";
 * NULL-terminated. */
extern const char *const bench_operands[];

/* Runs the kernel `what` (an operand) on cfg's scene. */
int bench_run(const char *what, const RunConfig *cfg);

#endif
