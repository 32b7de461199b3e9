/* Preconditioned MINRES (Paige & Saunders 1975, "Solution of sparse
 * indefinite systems of linear equations", SIAM J. Numer. Anal. 12(4); in
 * the preconditioned Lanczos form given by Elman, Silvester & Wathen,
 * "Finite Elements and Fast Iterative Solvers", OUP) for A x = b with
 * A symmetric, possibly indefinite, from x = 0.
 *
 * The preconditioner M (an InvApprox applied as z = M^-1 v, NULL = identity)
 * must be symmetric positive definite; the iterate minimises the residual in
 * the M^-1 norm over the Krylov space, which the recurrence gives for free:
 * |eta_j| = ||b - A x_j||_{M^-1}. Stop when |eta| < rel_tol ||b||_{M^-1}, after
 * max_iters iterations (capped), or at the deadline (timed_out). Vectors are
 * kept in the projected (free) subspace, as in pcg.h. A preconditioner that
 * is not positive (v^T M^-1 v < 0) or a non-finite value returns
 * MPM_ENUMERIC. Used by the semi-implicit method (Stomakhin et al. 2013's
 * linearised step, whose Hessian may be indefinite). */
#ifndef MPM_MINRES_H
#define MPM_MINRES_H

#include "solvers/inverse_approx.h"

typedef struct {
    double rel_tol;
    int max_iters;
    Deadline deadline; /* past it no iteration starts (zero-initialised: none) */
} MinresOptions;

typedef struct {
    int iters;
    int capped, timed_out;
    double res0, res; /* ||b||_{M^-1} and the final ||b - A x||_{M^-1} */
} MinresResult;

typedef struct {
    int cap_nodes;
    double *v0, *v1, *z, *zn, *w0, *w1, *q;
} MinresWork;

int minres_solve(const LinearOp *A, InvApprox *M, const Projection *proj, const double *b, double *x,
                 const MinresOptions *opt, MinresWork *work, MinresResult *res);
void minres_work_free(MinresWork *w);

#endif
