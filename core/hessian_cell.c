#include "core/hessian_cell.h"

#include <string.h>

/* Four doubles: one AVX2 register, two SSE registers in the portable build.
 * GCC/clang vector extensions, so one source serves both instruction sets
 * (this file is compiled with -ffp-contract=fast: a*b + c becomes an FMA
 * where the instruction set has one). */
typedef double v4d __attribute__((vector_size(32)));

#define LD HESSIAN_CELL_LD
#define CHUNK 8 /* particles prepared at a time: 54 KB of scratch */

/* Unaligned loads and stores (macros: a v4d by value crosses no function
 * boundary, which keeps the portable build's ABI out of it). */
#define LOAD4(v, p) memcpy(&(v), (p), sizeof(v4d))
#define STORE4(p, v) memcpy((p), &(v), sizeof(v4d))

/* One particle, ready for the pair products: at[d][t] = a_t(d) (zero in the
 * padding column) and Bt[3 ac + d][s] = s_p sum_b A[(a,b),(c,d)] a_s(b). */
typedef struct {
    double at[3][LD];
    double Bt[27][LD];
} Prep;

static inline __attribute__((always_inline)) void prepare(const double *A, const double *a, double sp, Prep *q)
{
    /* built in registers: a store followed by a wider load of the same
     * bytes would stall on store forwarding */
    v4d sa[3][LD / 4];
    for (int b = 0; b < 3; ++b)
        for (int v = 0; v < LD / 4; ++v) {
            const double *av = a + 12 * v + b;
            v4d x = {av[0], av[3], av[6], v < LD / 4 - 1 ? av[9] : 0.0}; /* t = 27 is padding */
            STORE4(q->at[b] + 4 * v, x);
            sa[b][v] = sp * x;
        }
    for (int ac = 0; ac < 9; ++ac)
        for (int d = 0; d < 3; ++d) {
            /* A[(a,b),(c,d)] for b = 0, 1, 2 */
            const double *Acol = A + 9 * (3 * (ac / 3)) + 3 * (ac % 3) + d;
            double c0 = Acol[0], c1 = Acol[9], c2 = Acol[18];
            double *row = q->Bt[3 * ac + d];
            for (int v = 0; v < LD / 4; ++v) {
                v4d r = c0 * sa[0][v] + c1 * sa[1][v] + c2 * sa[2][v];
                STORE4(row + 4 * v, r);
            }
        }
}

/* K[s][ac][4v..4v+3] (+)= sum_p sum_d Bt_p[3 ac + d][s] at_p[d][4v..4v+3]:
 * nine accumulators (the nine entries of four blocks) stay in registers
 * while the cell's particles stream by. */
static inline __attribute__((always_inline)) void pairs(int n, const Prep *q, double *K, int first)
{
    for (int s = 0; s < 27; ++s) {
        for (int v = s / 4; v < LD / 4; ++v) {
            double *Ks = K + 9 * LD * s + 4 * v;
            v4d acc[9];
#pragma GCC unroll 9
            for (int ac = 0; ac < 9; ++ac) {
                acc[ac] = (v4d){0.0, 0.0, 0.0, 0.0};
                if (!first) LOAD4(acc[ac], Ks + LD * ac);
            }
            for (int p = 0; p < n; ++p) {
                const Prep *qp = q + p;
                v4d x, y, z;
                LOAD4(x, qp->at[0] + 4 * v);
                LOAD4(y, qp->at[1] + 4 * v);
                LOAD4(z, qp->at[2] + 4 * v);
#pragma GCC unroll 9
                for (int ac = 0; ac < 9; ++ac) {
                    acc[ac] += qp->Bt[3 * ac][s] * x;
                    acc[ac] += qp->Bt[3 * ac + 1][s] * y;
                    acc[ac] += qp->Bt[3 * ac + 2][s] * z;
                }
            }
#pragma GCC unroll 9
            for (int ac = 0; ac < 9; ++ac) STORE4(Ks + LD * ac, acc[ac]);
        }
    }
}

static inline __attribute__((always_inline)) void cell_body(int n, const double *A, const double *a,
                                                            const double *vol, double scale, double *K)
{
    _Alignas(32) Prep q[CHUNK];
    for (int p0 = 0; p0 < n; p0 += CHUNK) {
        int m = n - p0 < CHUNK ? n - p0 : CHUNK;
        for (int p = 0; p < m; ++p)
            prepare(A + 81 * (size_t)(p0 + p), a + 81 * (size_t)(p0 + p), scale * vol[p0 + p], q + p);
        pairs(m, q, K, p0 == 0);
    }
}

static void cell_portable(int n, const double *A, const double *a, const double *vol, double scale, double *K)
{
    cell_body(n, A, a, vol, scale, K);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define HAVE_AVX2_CLONE 1
__attribute__((target("avx2,fma"))) static void cell_avx2(int n, const double *A, const double *a,
                                                           const double *vol, double scale, double *K)
{
    cell_body(n, A, a, vol, scale, K);
}

static int cpu_has_avx2(void) { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }
#endif

void hessian_cell(int n, const double *A, const double *a, const double *vol, double scale, double *K, int kernel)
{
    if (n <= 0) return;
#ifdef HAVE_AVX2_CLONE
    if (kernel == HESSIAN_CELL_AUTO && cpu_has_avx2()) {
        cell_avx2(n, A, a, vol, scale, K);
        return;
    }
#else
    (void)kernel; /* off x86-64 the portable kernel is the only one */
#endif
    cell_portable(n, A, a, vol, scale, K);
}

const char *hessian_cell_isa(void)
{
#ifdef HAVE_AVX2_CLONE
    if (cpu_has_avx2()) return "avx2+fma";
#endif
    return "portable";
}
