#include "core/vec.h"

#include <omp.h>
#include <string.h>

#include "core/mat3.h"

#define MAX_THREADS 256

double vec_dot(size_t len, const double *a, const double *b)
{
    double part[MAX_THREADS] = {0};
    int nt = 1;
#pragma omp parallel
    {
        int t = omp_get_thread_num();
#pragma omp single
        nt = omp_get_num_threads();
        double s = 0.0;
#pragma omp for schedule(static)
        for (size_t i = 0; i < len; ++i) s += a[i] * b[i];
        if (t < MAX_THREADS) part[t] = s;
    }
    double s = 0.0;
    for (int t = 0; t < nt && t < MAX_THREADS; ++t) s += part[t];
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
    if (x != y) memcpy(y, x, len * sizeof(double));
}

void vec_zero(size_t len, double *x) { memset(x, 0, len * sizeof(double)); }

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
