#include "core/reduce.h"

double reduce_sum(size_t n, size_t min_chunk, RangeSumFn fn, const void *ctx)
{
    if (n == 0) return 0.0;
    if (min_chunk < 1) min_chunk = 1;
    size_t chunks = (n + min_chunk - 1) / min_chunk;
    if (chunks > REDUCE_MAX_CHUNKS) chunks = REDUCE_MAX_CHUNKS;
    double part[REDUCE_MAX_CHUNKS];
    /* chunk c covers [n c / chunks, n (c + 1) / chunks): a function of n only */
#pragma omp parallel for schedule(static)
    for (size_t c = 0; c < chunks; ++c) part[c] = fn(ctx, n * c / chunks, n * (c + 1) / chunks);
    double s = 0.0;
    for (size_t c = 0; c < chunks; ++c) s += part[c];
    return s;
}
