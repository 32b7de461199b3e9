#include "core/vec.h"

#include <string.h>

#include "core/mat3.h"
#include "core/reduce.h"

typedef struct {
    const double *a, *b;
} DotArgs;

static double dot_range(const void *ctx, size_t begin, size_t end)
{
    const DotArgs *d = ctx;
    double s = 0.0;
    for (size_t i = begin; i < end; ++i) s += d->a[i] * d->b[i];
    return s;
}

static const CommOps *g_ranks; /* vec_sum_over_ranks */

void vec_sum_over_ranks(const CommOps *comm) { g_ranks = comm; }

double vec_dot(size_t len, const double *a, const double *b)
{
    DotArgs d = {a, b};
    double s = reduce_sum(len, 4096, dot_range, &d);
    if (g_ranks && g_ranks->sum(g_ranks->ctx, &s, 1)) return NAN;
    return s;
}

double vec_norm(size_t len, const double *a) { return sqrt(vec_dot(len, a, a)); }

void vec_axpy(size_t len, double alpha, const double *restrict x, double *restrict y)
{
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < len; ++i) y[i] += alpha * x[i];
}

void vec_xpby(size_t len, const double *restrict x, double beta, double *restrict y)
{
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < len; ++i) y[i] = x[i] + beta * y[i];
}

void vec_copy(size_t len, const double *x, double *y)
{
    if (x != y && len) memcpy(y, x, len * sizeof(double));
}

void vec_zero(size_t len, double *x)
{
    if (len) memset(x, 0, len * sizeof(double));
}

void vec_scale(size_t len, double alpha, double *x)
{
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < len; ++i) x[i] *= alpha;
}

void vec_block_apply(size_t n_nodes, const double *D, const double *r, double *z)
{
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < n_nodes; ++i) m3_mulv(D + 9 * i, r + 3 * i, z + 3 * i);
}
