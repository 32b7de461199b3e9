/* The fixed-corotated tangent dP/dF of four particles in SIMD lanes:
 * fcr_dPdF (core/fcr.c) transcribed to AVX intrinsics on the lane SVD of
 * core/fcr4.c, each expression in the scalar code's order (compiled, like
 * fcr4.c, without FMA contraction, -std=c11), so every lane equals
 * fcr_dPdF's A bit for bit (tests/unit/test_energy_kernel.c checks it).
 * See fcr4.h. */
#include <math.h>

#include "core/fcr.h"
#include "core/fcr4.h"
#include "core/fcr4_lanes.h"

static void dPdF4_portable(const double *F, const double *mu, const double *lambda, int projected, double *A)
{
    for (int l = 0; l < 4; ++l) fcr_dPdF(F + 9 * l, mu[l], lambda[l], projected, A + 81 * l);
}

#ifdef HAVE_AVX_CLONE

/* The lanes of x as doubles (x[l] by lane). */
typedef union {
    V v;
    double d[4];
} Lanes;

/* Ahat's PSD projection (fcr_sym3_clamp_psd) on the lanes whose Ahat fails
 * its positive-definiteness test, which is evaluated here in lanes with the
 * scalar test's operations (a lane that passes is left unchanged there). */
AVX static void clamp_lanes(V Ah[3][3])
{
    V m2 = sub(mul(Ah[0][0], Ah[1][1]), mul(Ah[0][1], Ah[0][1]));
    V det = add(sub(mul(Ah[0][0], sub(mul(Ah[1][1], Ah[2][2]), mul(Ah[1][2], Ah[1][2]))),
                    mul(Ah[0][1], sub(mul(Ah[0][1], Ah[2][2]), mul(Ah[1][2], Ah[0][2])))),
                mul(Ah[0][2], sub(mul(Ah[0][1], Ah[1][2]), mul(Ah[1][1], Ah[0][2]))));
    V zero = _mm256_setzero_pd();
    V pd = _mm256_and_pd(_mm256_and_pd(_mm256_cmp_pd(Ah[0][0], zero, _CMP_GT_OQ), _mm256_cmp_pd(m2, zero, _CMP_GT_OQ)),
                         _mm256_cmp_pd(det, zero, _CMP_GT_OQ));
    int pending = ~_mm256_movemask_pd(pd) & 15;
    if (!pending) return;
    Lanes a[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) a[i][j].v = Ah[i][j];
    for (int l = 0; l < 4; ++l) {
        if (!((pending >> l) & 1)) continue;
        double s[3][3];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) s[i][j] = a[i][j].d[l];
        fcr_sym3_clamp_psd(s);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) a[i][j].d[l] = s[i][j];
    }
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) Ah[i][j] = a[i][j].v;
}

/* x < 0 ? 0 : x (keeps -0 and NaN as the scalar `if` does) */
AVXI V clamp0(V x)
{
    V zero = _mm256_setzero_pd();
    return sel(_mm256_cmp_pd(x, zero, _CMP_LT_OQ), zero, x);
}

/* Writes out[e] (entry e of the four A's) to A + 81 l, four entries at a
 * time by 4x4 transposes. */
AVXI void store_lanes(const V out[81], double *A)
{
    int e = 0;
    for (; e + 4 <= 81; e += 4) {
        V t0 = _mm256_unpacklo_pd(out[e], out[e + 1]), t1 = _mm256_unpackhi_pd(out[e], out[e + 1]);
        V t2 = _mm256_unpacklo_pd(out[e + 2], out[e + 3]), t3 = _mm256_unpackhi_pd(out[e + 2], out[e + 3]);
        _mm256_storeu_pd(A + e, _mm256_permute2f128_pd(t0, t2, 0x20));
        _mm256_storeu_pd(A + 81 + e, _mm256_permute2f128_pd(t1, t3, 0x20));
        _mm256_storeu_pd(A + 162 + e, _mm256_permute2f128_pd(t0, t2, 0x31));
        _mm256_storeu_pd(A + 243 + e, _mm256_permute2f128_pd(t1, t3, 0x31));
    }
    for (; e < 81; ++e) {
        Lanes x = {.v = out[e]};
        for (int l = 0; l < 4; ++l) A[81 * l + e] = x.d[l];
    }
}

/* fcr_dPdF on four lanes; returns the lanes (bits) that need svd3's
 * rank-deficient branch. Names follow fcr_dPdF. */
AVX static int dPdF4_avx(const double *F, const double *mu, const double *lambda, int projected, double *A)
{
    V f[9];
    for (int e = 0; e < 9; ++e) f[e] = _mm256_setr_pd(F[e], F[9 + e], F[18 + e], F[27 + e]);
    V u[3][3], v[3][3], s[3]; /* U[3i+k] = u[k][i], V[3j+k] = v[k][j] */
    /* A's 41 cache lines fetched for writing while the SVD runs */
    for (int c = 0; c < 324; c += 8) __builtin_prefetch(A + c, 1, 3);
    __builtin_prefetch(A + 323, 1, 3);
    int redo = fcr4_svd_avx(f, u, v, s);

    V one = cst(1.0);
    V vmu = _mm256_loadu_pd(mu), vla = _mm256_loadu_pd(lambda);
    V J = mul(mul(s[0], s[1]), s[2]);
    V Sk[3] = {mul(s[1], s[2]), mul(s[0], s[2]), mul(s[0], s[1])};
    V lj = mul(vla, sub(J, one));
    V mu2 = mul(cst(2.0), vmu);
    V ph[3];
    for (int k = 0; k < 3; ++k) ph[k] = add(mul(mu2, sub(s[k], one)), mul(lj, Sk[k]));

    V Ah[3][3];
    for (int k = 0; k < 3; ++k) Ah[k][k] = add(mu2, mul(mul(vla, Sk[k]), Sk[k]));
    Ah[0][1] = Ah[1][0] = add(mul(lj, s[2]), mul(mul(vla, Sk[0]), Sk[1]));
    Ah[0][2] = Ah[2][0] = add(mul(lj, s[1]), mul(mul(vla, Sk[0]), Sk[2]));
    Ah[1][2] = Ah[2][1] = add(mul(lj, s[0]), mul(mul(vla, Sk[1]), Sk[2]));

    static const int PK[3] = {0, 1, 2}, PL[3] = {1, 2, 0}, PM[3] = {2, 0, 1};
    V mc[3], pc[3];
    for (int e = 0; e < 3; ++e) {
        int k = PK[e], l = PL[e], m = PM[e];
        mc[e] = sub(mu2, mul(lj, s[m]));
        V den = add(s[k], s[l]);
        den = sel(_mm256_cmp_pd(vabs(den), cst(1e-6), _CMP_LT_OQ), csign(cst(1e-6), den), den);
        pc[e] = dvd(add(ph[k], ph[l]), den);
    }

    if (projected) {
        clamp_lanes(Ah);
        for (int e = 0; e < 3; ++e) {
            mc[e] = clamp0(mc[e]);
            pc[e] = clamp0(pc[e]);
        }
    }

    /* Rank-9 sum A = sum_e x_e y_e^T, upper triangle, then mirrored. */
    V X[9][9], Y[9][9];
    V Mkk[3][9];
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) Mkk[k][3 * i + j] = mul(u[k][i], v[k][j]);
    for (int k = 0; k < 3; ++k)
        for (int x = 0; x < 9; ++x) {
            X[k][x] = Mkk[k][x];
            Y[k][x] = add(add(mul(Ah[k][0], Mkk[0][x]), mul(Ah[k][1], Mkk[1][x])), mul(Ah[k][2], Mkk[2][x]));
        }
    V half = cst(0.5);
    for (int e = 0; e < 3; ++e) {
        int k = PK[e], l = PL[e];
        V hm = mul(half, mc[e]), hp = mul(half, pc[e]);
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                V kl = mul(u[k][i], v[l][j]), lk = mul(u[l][i], v[k][j]);
                V sp = add(kl, lk), sm = sub(kl, lk);
                X[3 + 2 * e][3 * i + j] = mul(hm, sp);
                Y[3 + 2 * e][3 * i + j] = sp;
                X[4 + 2 * e][3 * i + j] = mul(hp, sm);
                Y[4 + 2 * e][3 * i + j] = sm;
            }
    }
    V out[81];
    for (int i = 0; i < 9; ++i)
        for (int j = i; j < 9; ++j) {
            V a = _mm256_setzero_pd(); /* the scalar sum starts at +0.0 */
            for (int e = 0; e < 9; ++e) a = add(a, mul(X[e][i], Y[e][j]));
            out[9 * i + j] = out[9 * j + i] = a;
        }
    store_lanes(out, A);
    return redo;
}
#endif

void fcr_dPdF4(const double *F, const double *mu, const double *lambda, int projected, double *A, int kernel)
{
#ifdef HAVE_AVX_CLONE
    if (kernel == FCR4_AUTO && fcr4_cpu_has_avx()) {
        int redo = dPdF4_avx(F, mu, lambda, projected, A);
        for (int l = 0; l < 4; ++l)
            if (((redo >> l) & 1) || !fcr4_usual(F + 9 * l))
                fcr_dPdF(F + 9 * l, mu[l], lambda[l], projected, A + 81 * l);
        return;
    }
#else
    (void)kernel; /* off x86-64 the portable lanes are the only ones */
#endif
    dPdF4_portable(F, mu, lambda, projected, A);
}
