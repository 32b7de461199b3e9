/* Sums whose result does not depend on the thread count.
 *
 * A per-thread partial sum changes its rounding with the number of threads
 * (and a fixed-size table of partials silently dropped threads past its
 * size). Here the index range [0, n) is cut into chunks by n alone, each
 * chunk is summed in index order by whichever thread runs it, and the chunk
 * sums are added in chunk order: 1, 2 or 1,000 threads give the same bits,
 * so runs are reproducible across machines and --threads values. */
#ifndef MPM_REDUCE_H
#define MPM_REDUCE_H

#include <stddef.h>

/* Chunks per sum: bounds the stack table of chunk sums and the threads a
 * sum can use (MPM_MAX_THREADS in core/threads.h is the same number). */
enum { REDUCE_MAX_CHUNKS = 1024 };

/* Sum of the terms with indices [begin, end), in index order. */
typedef double (*RangeSumFn)(const void *ctx, size_t begin, size_t end);

/* sum_{i < n} term_i, chunks of at least min_chunk indices (fewer chunks for
 * cheap terms keep the per-chunk call overhead small). OpenMP-parallel over
 * chunks; call it outside parallel regions. */
double reduce_sum(size_t n, size_t min_chunk, RangeSumFn fn, const void *ctx);

#endif
