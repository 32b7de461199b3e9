/* Inexact PCG as an inverse-Hessian approximation (LBFGS-H of the HOT study,
 * SPEC 7; reference §6.3): z = PCG(H, q) from zero with 3x3 block-Jacobi,
 * stopped when sqrt(r^T D^-1 r) < 1/2 sqrt(q^T D^-1 q), at most 10000
 * iterations (option "max_iters"). The same rule is the coarsest-level solve
 * of the multigrid V-cycle. */
#ifndef MPM_PCG_INVERSE_H
#define MPM_PCG_INVERSE_H

#include "solvers/inverse_approx.h"

extern const InvApproxOps inv_inexact_pcg_ops;

#endif
