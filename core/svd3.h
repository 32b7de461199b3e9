/* Robust 3x3 singular value decomposition, rotation variant.
 *
 * F = U diag(sigma) V^T with U and V proper rotations (det = +1).
 * sigma[0] >= sigma[1] >= |sigma[2]|; only sigma[2] may be negative (an
 * inverted F). Accurate for near-degenerate, rank-deficient, repeated and
 * inverted inputs (HOT reference §2 uses the same sign/sort convention). */
#ifndef MPM_SVD3_H
#define MPM_SVD3_H

void svd3(const double F[9], double U[9], double sigma[3], double V[9]);

#endif
