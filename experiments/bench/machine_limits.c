#include "experiments/bench/machine_limits.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/event_log.h"
#include "core/error.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define HAVE_X86_FMA_PATH 1
#endif

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double machine_best_time(void (*fn)(void *), void *ctx, double min_s, double *spread)
{
    enum { MAX_KEEP = 4096 };
    double *t = malloc(sizeof(double) * MAX_KEEP);
    double best = 1e300, start = event_clock();
    int reps = 0;
    while (reps < 3 || event_clock() - start < min_s) {
        double t0 = event_clock();
        fn(ctx);
        double dt = event_clock() - t0;
        if (dt < best) best = dt;
        if (t && reps < MAX_KEEP) t[reps] = dt;
        if (++reps > 100000) break;
    }
    if (spread) {
        *spread = 0.0;
        if (t) {
            int k = reps < MAX_KEEP ? reps : MAX_KEEP;
            qsort(t, (size_t)k, sizeof(double), cmp_double);
            *spread = (t[k / 2] - best) / best;
        }
    }
    free(t);
    return best;
}

typedef struct {
    double *a, *b, *c;
    size_t len;
} Triad;

static void run_triad(void *ctx)
{
    Triad *t = ctx;
    double *restrict a = t->a;
    const double *restrict b = t->b, *restrict c = t->c;
    const double s = 3.0;
#pragma omp parallel for schedule(static)
    for (size_t i = 0; i < t->len; ++i) a[i] = b[i] + s * c[i];
}

int machine_stream_triad(size_t len, double min_s, double *seconds, double *gbs)
{
    Triad t = {malloc(sizeof(double) * len), malloc(sizeof(double) * len), malloc(sizeof(double) * len), len};
    int status = MPM_OK;
    if (!t.a || !t.b || !t.c) {
        status = mpm_error(MPM_EINTERNAL, "out of memory in bench (triad of %zu doubles)", len);
    } else {
        /* first touch by the threads that run the triad (same static schedule) */
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < len; ++i) {
            t.a[i] = 0.0;
            t.b[i] = 1.0;
            t.c[i] = 2.0;
        }
        *seconds = machine_best_time(run_triad, &t, min_s, NULL);
        *gbs = 24.0 * (double)len / *seconds / 1e9;
    }
    free(t.a), free(t.b), free(t.c);
    return status;
}

/* Per thread: `iters` rounds of NCHAIN independent x <- x m + c chains
 * (m < 1, so they converge to c / (1 - m) and stay normal). */
#define NCHAIN 16
static double chains_build(long iters)
{
    double x[NCHAIN];
    for (int j = 0; j < NCHAIN; ++j) x[j] = 1.0 + 1e-3 * j;
    const double m = 0.9999999, c = 1e-7;
    for (long it = 0; it < iters; ++it)
        for (int j = 0; j < NCHAIN; ++j) x[j] = x[j] * m + c;
    double s = 0;
    for (int j = 0; j < NCHAIN; ++j) s += x[j];
    return s;
}

#ifdef HAVE_X86_FMA_PATH
/* 12 independent 4-wide FMA chains: Zen 3 / Haswell+ have two FMA pipes of
 * latency 4-5, so 8-10 chains in flight saturate them. */
__attribute__((target("avx2,fma"))) static double chains_avx2(long iters)
{
    const __m256d m = _mm256_set1_pd(0.9999999), c = _mm256_set1_pd(1e-7);
    __m256d x0 = _mm256_set1_pd(1.0), x1 = _mm256_set1_pd(1.1), x2 = _mm256_set1_pd(1.2), x3 = _mm256_set1_pd(1.3),
            x4 = _mm256_set1_pd(1.4), x5 = _mm256_set1_pd(1.5), x6 = _mm256_set1_pd(1.6), x7 = _mm256_set1_pd(1.7),
            x8 = _mm256_set1_pd(1.8), x9 = _mm256_set1_pd(1.9), x10 = _mm256_set1_pd(2.0), x11 = _mm256_set1_pd(2.1);
    for (long it = 0; it < iters; ++it) {
        x0 = _mm256_fmadd_pd(x0, m, c);
        x1 = _mm256_fmadd_pd(x1, m, c);
        x2 = _mm256_fmadd_pd(x2, m, c);
        x3 = _mm256_fmadd_pd(x3, m, c);
        x4 = _mm256_fmadd_pd(x4, m, c);
        x5 = _mm256_fmadd_pd(x5, m, c);
        x6 = _mm256_fmadd_pd(x6, m, c);
        x7 = _mm256_fmadd_pd(x7, m, c);
        x8 = _mm256_fmadd_pd(x8, m, c);
        x9 = _mm256_fmadd_pd(x9, m, c);
        x10 = _mm256_fmadd_pd(x10, m, c);
        x11 = _mm256_fmadd_pd(x11, m, c);
    }
    __m256d s = _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(x0, x1), _mm256_add_pd(x2, x3)),
                              _mm256_add_pd(_mm256_add_pd(x4, x5), _mm256_add_pd(x6, x7)));
    s = _mm256_add_pd(s, _mm256_add_pd(_mm256_add_pd(x8, x9), _mm256_add_pd(x10, x11)));
    double out[4];
    _mm256_storeu_pd(out, s);
    return out[0] + out[1] + out[2] + out[3];
}
#endif

typedef struct {
    int avx2;
    long iters;
    double sink;
} PeakCtx;

static void run_peak(void *ctx)
{
    PeakCtx *p = ctx;
    double sink = 0;
#pragma omp parallel reduction(+ : sink)
    {
#ifdef HAVE_X86_FMA_PATH
        if (p->avx2) sink += chains_avx2(p->iters);
        else
#endif
            sink += chains_build(p->iters);
    }
    p->sink += sink;
}

void machine_flop_peak(double min_s, FlopPeak *out)
{
    int threads = omp_get_max_threads();
    PeakCtx p = {0, 2000000, 0.0};
    double t = machine_best_time(run_peak, &p, min_s, NULL);
    out->gflops_build = 2.0 * NCHAIN * (double)p.iters * threads / t / 1e9;
    out->gflops_machine = out->gflops_build;
    out->isa = "build's multiply-add";
#ifdef HAVE_X86_FMA_PATH
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
        p.avx2 = 1;
        p.iters = 2000000;
        t = machine_best_time(run_peak, &p, min_s, NULL);
        out->gflops_machine = 2.0 * 12 * 4 * (double)p.iters * threads / t / 1e9;
        out->isa = "avx2+fma";
    }
#endif
    if (!isfinite(p.sink)) out->gflops_machine = out->gflops_build = 0.0; /* keeps the chains live */
}
