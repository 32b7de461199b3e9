/* Internal to core/fcr4.c and core/fcr_tangent4.c: the AVX lane helpers and
 * the four-lane SVD they share (see fcr4.h). Every helper is one
 * instruction of the scalar code's operation, so a lane rounds as the
 * scalar expression does; with no FMA contraction (-std=c11) the lanes give
 * svd3's and fcr.c's bits. */
#ifndef MPM_FCR4_LANES_H
#define MPM_FCR4_LANES_H

/* svd3 takes its ordinary path for F (no scaling, no special case): the
 * lanes are valid only there. */
int fcr4_usual(const double *F);

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define HAVE_AVX_CLONE 1

typedef __m256d V;
#define AVX __attribute__((target("avx")))
#define AVXI static inline __attribute__((target("avx"), always_inline))

AVXI V add(V a, V b) { return _mm256_add_pd(a, b); }
AVXI V sub(V a, V b) { return _mm256_sub_pd(a, b); }
AVXI V mul(V a, V b) { return _mm256_mul_pd(a, b); }
AVXI V dvd(V a, V b) { return _mm256_div_pd(a, b); }
AVXI V sqr(V a) { return _mm256_sqrt_pd(a); }
AVXI V cst(double x) { return _mm256_set1_pd(x); }
/* m ? a : b per lane */
AVXI V sel(V m, V a, V b) { return _mm256_blendv_pd(b, a, m); }
AVXI V neg(V a) { return _mm256_xor_pd(a, cst(-0.0)); }
AVXI V vabs(V a) { return _mm256_andnot_pd(cst(-0.0), a); }
/* copysign(x, y) */
AVXI V csign(V x, V y) { return _mm256_or_pd(vabs(x), _mm256_and_pd(cst(-0.0), y)); }
AVXI V dot3(const V x[3], const V y[3]) { return add(add(mul(x[0], y[0]), mul(x[1], y[1])), mul(x[2], y[2])); }

/* svd3 on four lanes: f[e] holds entry e of the four F's. Returns
 * u[k][r] = U[3r+k], v[k][r] = V[3r+k], sg[k] = sigma[k] per lane, and the
 * lanes (bits) that need svd3's rank-deficient branch (their output is not
 * svd3's). Valid in the lanes where fcr4_usual holds. */
AVX int fcr4_svd_avx(const V f[9], V u[3][3], V v[3][3], V sg[3]);

static inline int fcr4_cpu_has_avx(void) { return __builtin_cpu_supports("avx"); }
#endif

#endif
