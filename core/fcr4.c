/* Four fixed-corotated particles in SIMD lanes: core/svd3.c's one-sided
 * Jacobi SVD and fcr_psi_P (core/fcr.c) transcribed to AVX intrinsics, each
 * expression in the scalar code's order (this file is compiled without FMA
 * contraction, -std=c11), so every lane equals the scalar result bit for bit
 * (tests/unit/test_energy_kernel.c checks it). See fcr4.h. */
#include "core/fcr4.h"

#include <float.h>
#include <math.h>

#include "core/fcr.h"
#include "core/fcr4_lanes.h"
#include "core/svd3.h"

static void fcr4_portable(const double *F, const double *mu, const double *lambda, double *P, double psi[4])
{
    for (int l = 0; l < 4; ++l) psi[l] = fcr_psi_P(F + 9 * l, mu[l], lambda[l], P + 9 * l);
}

/* NaN is tested first, so a compare replaces fmax (a libm call here). */
int fcr4_usual(const double *F)
{
    double m = 0.0;
    for (int k = 0; k < 9; ++k) {
        double a = fabs(F[k]);
        if (isnan(a)) return 0;
        if (a > m) m = a;
    }
    return m >= 0x1p-128 && m <= 0x1p128;
}

#ifdef HAVE_AVX_CLONE

/* svd3.c jacobi_pair on the lanes that need a rotation; returns them as bits. */
AVXI int jacobi4(V ci[3], V cj[3], V vi[3], V vj[3])
{
    V a = dot3(ci, ci), b = dot3(cj, cj), g = dot3(ci, cj);
    V rot = _mm256_cmp_pd(mul(g, g), mul(cst(SVD3_TOL * SVD3_TOL), mul(a, b)), _CMP_GT_OQ);
    int bits = _mm256_movemask_pd(rot);
    if (!bits) return 0;
    V d = sub(b, a), ad = vabs(d);
    V r = sqr(add(mul(d, d), mul(mul(cst(4.0), g), g)));
    V t = dvd(mul(csign(cst(1.0), d), mul(cst(2.0), g)), add(ad, r));
    V c = sqr(dvd(add(r, ad), mul(cst(2.0), r))), s = mul(t, c);
    for (int k = 0; k < 3; ++k) {
        V x = ci[k], y = cj[k];
        ci[k] = sel(rot, sub(mul(c, x), mul(s, y)), x);
        cj[k] = sel(rot, add(mul(s, x), mul(c, y)), y);
        x = vi[k];
        y = vj[k];
        vi[k] = sel(rot, sub(mul(c, x), mul(s, y)), x);
        vj[k] = sel(rot, add(mul(s, x), mul(c, y)), y);
    }
    return bits;
}

/* svd3.c swap_cols where m is set */
AVXI void swap4(V c[3][3], V v[3][3], V n2[3], int i, int j, V m)
{
    for (int k = 0; k < 3; ++k) {
        V t = c[i][k];
        c[i][k] = sel(m, c[j][k], t);
        c[j][k] = sel(m, neg(t), c[j][k]);
        t = v[i][k];
        v[i][k] = sel(m, v[j][k], t);
        v[j][k] = sel(m, neg(t), v[j][k]);
    }
    V t = n2[i];
    n2[i] = sel(m, n2[j], t);
    n2[j] = sel(m, t, n2[j]);
}

AVX int fcr4_svd_avx(const V f[9], V u[3][3], V v[3][3], V sg[3])
{
    /* c[k] = column k of F, v[k] = column k of V */
    V c[3][3];
    for (int k = 0; k < 3; ++k)
        for (int r = 0; r < 3; ++r) {
            c[k][r] = f[3 * r + k];
            v[k][r] = cst(k == r ? 1.0 : 0.0);
        }
    for (int sweep = 0; sweep < SVD3_MAX_SWEEPS; ++sweep) {
        int rot = jacobi4(c[0], c[1], v[0], v[1]);
        rot |= jacobi4(c[0], c[2], v[0], v[2]);
        rot |= jacobi4(c[1], c[2], v[1], v[2]);
        if (!rot) break;
    }
    V n2[3];
    for (int k = 0; k < 3; ++k) n2[k] = dot3(c[k], c[k]);
    swap4(c, v, n2, 0, 1, _mm256_cmp_pd(n2[0], n2[1], _CMP_LT_OQ));
    swap4(c, v, n2, 1, 2, _mm256_cmp_pd(n2[1], n2[2], _CMP_LT_OQ));
    swap4(c, v, n2, 0, 1, _mm256_cmp_pd(n2[0], n2[1], _CMP_LT_OQ));

    V s0 = sqr(n2[0]);
    for (int k = 0; k < 3; ++k) u[0][k] = dvd(c[0][k], s0);
    V d = dot3(u[0], c[1]);
    V w[3];
    for (int k = 0; k < 3; ++k) w[k] = sub(c[1][k], mul(d, u[0][k]));
    V wn2 = dot3(w, w);
    int rank1 = _mm256_movemask_pd(_mm256_cmp_pd(wn2, cst(SVD3_TINY2), _CMP_NGT_UQ)); /* !(wn2 > SVD3_TINY2) */
    V wn = sqr(wn2);
    for (int k = 0; k < 3; ++k) u[1][k] = dvd(w[k], wn);
    u[2][0] = sub(mul(u[0][1], u[1][2]), mul(u[0][2], u[1][1]));
    u[2][1] = sub(mul(u[0][2], u[1][0]), mul(u[0][0], u[1][2]));
    u[2][2] = sub(mul(u[0][0], u[1][1]), mul(u[0][1], u[1][0]));
    V proj = dot3(u[2], c[2]);
    sg[0] = s0;
    sg[1] = sqr(n2[1]);
    sg[2] = csign(sqr(n2[2]), proj);
    return rank1;
}

/* Returns the lanes (bits) that need svd3's rank-deficient branch. */
AVX static int fcr4_avx(const double *F, const double *mu, const double *lambda, double *P, double psi[4])
{
    V f[9];
    for (int e = 0; e < 9; ++e) f[e] = _mm256_setr_pd(F[e], F[9 + e], F[18 + e], F[27 + e]);
    V u[3][3], v[3][3], sg[3];
    int rank1 = fcr4_svd_avx(f, u, v, sg);

    /* fcr_psi_P: R = U V^T (U[3r+k] = u[k][r], V likewise), cof F, P, psi */
    V one = cst(1.0);
    V J = mul(mul(sg[0], sg[1]), sg[2]);
    V vmu = _mm256_loadu_pd(mu), vla = _mm256_loadu_pd(lambda);
    V C[9];
    C[0] = sub(mul(f[4], f[8]), mul(f[5], f[7]));
    C[1] = sub(mul(f[5], f[6]), mul(f[3], f[8]));
    C[2] = sub(mul(f[3], f[7]), mul(f[4], f[6]));
    C[3] = sub(mul(f[2], f[7]), mul(f[1], f[8]));
    C[4] = sub(mul(f[0], f[8]), mul(f[2], f[6]));
    C[5] = sub(mul(f[1], f[6]), mul(f[0], f[7]));
    C[6] = sub(mul(f[1], f[5]), mul(f[2], f[4]));
    C[7] = sub(mul(f[2], f[3]), mul(f[0], f[5]));
    C[8] = sub(mul(f[0], f[4]), mul(f[1], f[3]));
    V Jm1 = sub(J, one);
    V lj = mul(vla, Jm1), mu2 = mul(cst(2.0), vmu);
    double out[9][4];
    for (int r = 0; r < 3; ++r)
        for (int cc = 0; cc < 3; ++cc) {
            V R = add(add(mul(u[0][r], v[0][cc]), mul(u[1][r], v[1][cc])), mul(u[2][r], v[2][cc]));
            int e = 3 * r + cc;
            _mm256_storeu_pd(out[e], add(mul(mu2, sub(f[e], R)), mul(lj, C[e])));
        }
    for (int l = 0; l < 4; ++l)
        for (int e = 0; e < 9; ++e) P[9 * l + e] = out[e][l];
    V d0 = sub(sg[0], one), d1 = sub(sg[1], one), d2 = sub(sg[2], one);
    V e = add(mul(vmu, add(add(mul(d0, d0), mul(d1, d1)), mul(d2, d2))), mul(mul(mul(cst(0.5), vla), Jm1), Jm1));
    _mm256_storeu_pd(psi, e);
    return rank1;
}
#endif

void fcr_psi_P4(const double *F, const double *mu, const double *lambda, double *P, double psi[4], int kernel)
{
#ifdef HAVE_AVX_CLONE
    if (kernel == FCR4_AUTO && fcr4_cpu_has_avx()) {
        int redo = fcr4_avx(F, mu, lambda, P, psi);
        for (int l = 0; l < 4; ++l)
            if (((redo >> l) & 1) || !fcr4_usual(F + 9 * l)) psi[l] = fcr_psi_P(F + 9 * l, mu[l], lambda[l], P + 9 * l);
        return;
    }
#else
    (void)kernel; /* off x86-64 the portable lanes are the only ones */
#endif
    fcr4_portable(F, mu, lambda, P, psi);
}

const char *fcr4_isa(void)
{
#ifdef HAVE_AVX_CLONE
    if (fcr4_cpu_has_avx()) return "avx";
#endif
    return "portable";
}
