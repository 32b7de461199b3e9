/* Jacobi inverse approximations (SPEC 5; HOT reference §4 step 4, §9.2).
 *
 *  - inv_block_jacobi_ops ("block-jacobi"): z_i = D_i^-1 r_i with D_i the
 *    node's 3x3 diagonal block of the BC-projected Hessian (the reference's
 *    -Ainv 1; the default "Jacobi" of every preset);
 *  - inv_scalar_jacobi_ops ("jacobi"): z = r / diag(H) entrywise
 *    (-Ainv 0).
 * Both need only InvSetupInput.diag, so they also serve matrix-free PN.
 * A singular or non-finite diagonal block (or zero diagonal entry) fails
 * setup with MPM_ENUMERIC naming the node: a numerical breakdown of the
 * step. */
#ifndef MPM_JACOBI_H
#define MPM_JACOBI_H

#include "solvers/inverse_approx.h"

extern const InvApproxOps inv_block_jacobi_ops;
extern const InvApproxOps inv_scalar_jacobi_ops;

/* Dinv_i = D_i^-1 for n nodes (9 doubles each), OpenMP-parallel. On a
 * singular or non-finite block returns MPM_ENUMERIC naming the lowest such
 * node; `what` prefixes the message (e.g. "block jacobi", "mg level 2"). */
int block_diag_invert(int n, const double *diag, double *dinv, const char *what);

#endif
