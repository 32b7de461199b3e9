#include "core/gradient_cell.h"

#include <string.h>

/* Four doubles (one AVX2 register, two SSE registers in the portable
 * build); this file is compiled with -ffp-contract=fast, as
 * core/hessian_cell.c, so a*b + c becomes an FMA where there is one. */
typedef double v4d __attribute__((vector_size(32)));

#define LOAD4(v, p) memcpy(&(v), (p), sizeof(v4d))
#define STORE4(p, v) memcpy((p), &(v), sizeof(v4d))

static inline __attribute__((always_inline)) void cell_body(int n, const double *P, const double *Fn,
                                                            const double *f1d, const double *vol, double scale,
                                                            double *out)
{
    v4d acc[27]; /* set by the first particle (no zeroing pass) */
    for (int p = 0; p < n; ++p) {
        const double *Pp = P + 9 * p, *F = Fn + 9 * p, *f = f1d + 18 * p;
        double s = scale * vol[p];
        double Q[9]; /* s P F^nT */
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                Q[3 * r + c] = s * (Pp[3 * r] * F[3 * c] + Pp[3 * r + 1] * F[3 * c + 1] + Pp[3 * r + 2] * F[3 * c + 2]);
        const double *N0 = f, *N1 = f + 3, *D0 = f + 9, *D1 = f + 12;
        v4d N2 = {f[6], f[7], f[8], 0.0}, D2 = {f[15], f[16], f[17], 0.0};
#pragma GCC unroll 3
        for (int a = 0; a < 3; ++a)
#pragma GCC unroll 3
            for (int b = 0; b < 3; ++b) {
                /* grad w over c, as core/grid.c forms it: ((x_a y_b) z_c) */
                v4d g0 = (D0[a] * N1[b]) * N2, g1 = (N0[a] * D1[b]) * N2, g2 = (N0[a] * N1[b]) * D2;
                v4d *A = acc + 3 * (3 * a + b);
                v4d x = Q[0] * g0 + Q[1] * g1 + Q[2] * g2, y = Q[3] * g0 + Q[4] * g1 + Q[5] * g2,
                    z = Q[6] * g0 + Q[7] * g1 + Q[8] * g2;
                if (p == 0) {
                    A[0] = x;
                    A[1] = y;
                    A[2] = z;
                } else {
                    A[0] += x;
                    A[1] += y;
                    A[2] += z;
                }
            }
    }
    for (int e = 0; e < 27; ++e) STORE4(out + 4 * e, acc[e]);
}

static void cell_portable(int n, const double *P, const double *Fn, const double *f1d, const double *vol,
                          double scale, double *out)
{
    cell_body(n, P, Fn, f1d, vol, scale, out);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define HAVE_AVX2_CLONE 1
__attribute__((target("avx2,fma"))) static void cell_avx2(int n, const double *P, const double *Fn,
                                                           const double *f1d, const double *vol, double scale,
                                                           double *out)
{
    cell_body(n, P, Fn, f1d, vol, scale, out);
}

static int cpu_has_avx2(void) { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }
#endif

void gradient_cell(int n, const double *P, const double *Fn, const double *f1d, const double *vol, double scale,
                   double *f, int kernel)
{
    if (n <= 0) return;
#ifdef HAVE_AVX2_CLONE
    if (kernel == GRADIENT_CELL_AUTO && cpu_has_avx2()) {
        cell_avx2(n, P, Fn, f1d, vol, scale, f);
        return;
    }
#else
    (void)kernel; /* off x86-64 the portable kernel is the only one */
#endif
    cell_portable(n, P, Fn, f1d, vol, scale, f);
}

const char *gradient_cell_isa(void)
{
#ifdef HAVE_AVX2_CLONE
    if (cpu_has_avx2()) return "avx2+fma";
#endif
    return "portable";
}
