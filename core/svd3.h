/* Robust 3x3 singular value decomposition, rotation variant.
 *
 * F = U diag(sigma) V^T with U and V proper rotations (det = +1).
 * sigma[0] >= sigma[1] >= |sigma[2]|; only sigma[2] may be negative (an
 * inverted F). Accurate for near-degenerate, rank-deficient, repeated and
 * inverted inputs (HOT reference §2 uses the same sign/sort convention). */
#ifndef MPM_SVD3_H
#define MPM_SVD3_H

#include <float.h>

void svd3(const double F[9], double U[9], double sigma[3], double V[9]);

/* The Jacobi iteration's constants, shared with the four-lane copy in
 * core/fcr4.c (which must give svd3's bits): at most this many sweeps;
 * pairs are treated as orthogonal when |ci.cj| <= SVD3_TOL |ci| |cj|; below
 * SVD3_TINY2 squared norm (relative to a largest column of norm ~1 after
 * scaling) a column carries no usable direction. */
enum { SVD3_MAX_SWEEPS = 16 };
#define SVD3_TOL (2.0 * DBL_EPSILON)
#define SVD3_TINY2 1e-280

#endif
