/* The machine's limits, measured in the process that quotes fractions of
 * them (every `mpmbench bench` target uses these, so a kernel's GB/s and
 * GFLOP/s are set against numbers taken on the same machine, threads and
 * moment):
 *  - STREAM triad a = b + s c (McCalpin's convention: 24 bytes per entry,
 *    write-allocate traffic not counted), best of repeated runs, over a
 *    working set chosen by the caller (far beyond the last-level cache for
 *    the DRAM bandwidth);
 *  - floating-point peak: independent chains of fused multiply-adds (2
 *    flops each), as many as hide the FMA latency, on every thread. Two
 *    numbers: with the widest FMA the CPU has (AVX2+FMA selected at run
 *    time on x86-64; the machine's peak) and with the instructions the
 *    build targets (plain multiply and add at the build's -march: the peak
 *    this build's kernels can reach). */
#ifndef MPM_MACHINE_LIMITS_H
#define MPM_MACHINE_LIMITS_H

#include <stddef.h>

/* Best triad time over len doubles per array (3 arrays, allocated for the
 * call) and its bandwidth in GB/s; min_s: minimum total measuring time. */
int machine_stream_triad(size_t len, double min_s, double *seconds, double *gbs);

typedef struct {
    double gflops_machine; /* widest FMA available at run time */
    double gflops_build;   /* multiply-add at the build's instruction set */
    const char *isa;       /* what gflops_machine used, e.g. "avx2+fma" or "scalar fma" */
} FlopPeak;

/* Floating-point peak with all OpenMP threads, each over min_s seconds. */
void machine_flop_peak(double min_s, FlopPeak *out);

/* Repeats fn(ctx) for at least min_s seconds and 3 times; returns the best
 * time and, when spread is not NULL, (median - best) / best of the reps. */
double machine_best_time(void (*fn)(void *), void *ctx, double min_s, double *spread);

#endif
