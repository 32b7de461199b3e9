/* Preconditioned conjugate gradients from x = 0 (SPEC 5).
 *
 * Stopping, on the preconditioned norm rho = sqrt(r^T z):
 *  - PCG_FORCING: eta = min(0.5, sqrt(max(rho0, tau))), stop when rho < eta rho0
 *    (the inexact-Newton forcing term of HOT §5 / reference §4);
 *  - PCG_ABSOLUTE: stop when rho < abs_tol (coarse solves, LBFGS-H: abs_tol
 *    = 1/2 sqrt(bbar^T D^-1 bbar), reference §5.3);
 *  - PCG_RELATIVE: stop when rho < rel_tol rho0, rel_tol given by the outer
 *    method (the HOT code's ConjugateGradient under USE_GAST15_METRIC, whose
 *    rel_tol is min(0.5, sqrt(max(||g||, tau_g))): reference §3 item 7);
 *  - PCG_RELATIVE_L2: stop when the unpreconditioned ||r||_2 < rel_tol ||r0||_2
 *    (Gast et al. 2015 §3.1: "solving the system to a relative tolerance").
 * The check is at the top of each iteration; at most max_iters iterations,
 * and none once `deadline` has passed (timed_out is set).
 * Vectors r, z and the search direction are kept in the projected subspace.
 * A variable preconditioner (InvApprox.flexible) gets flexible CG's beta.
 * Non-positive curvature of A along a search direction ends the solve as
 * Gast et al. 2015 §3.1 prescribe (indefinite = 1, see pcg.c); with a
 * projected (SPD) Hessian it does not happen, with Gast15's unprojected one
 * it is the method's exit.
 * A breakdown (r^T M^-1 r negative or not finite: the operator or the
 * preconditioner is not SPD, or the data hold NaN) returns MPM_ENUMERIC. */
#ifndef MPM_PCG_H
#define MPM_PCG_H

#include "solvers/inverse_approx.h"

typedef enum { PCG_FORCING = 0, PCG_ABSOLUTE = 1, PCG_RELATIVE = 2, PCG_RELATIVE_L2 = 3 } PcgStop;

typedef struct {
    PcgStop stop;
    double tau;      /* PCG_FORCING floor */
    double abs_tol;  /* PCG_ABSOLUTE */
    int max_iters;   /* 10000 in every reference configuration */
    Deadline deadline; /* past it no iteration starts (zero-initialised: none) */
    double rel_tol;  /* PCG_RELATIVE, PCG_RELATIVE_L2 */
} PcgOptions;

typedef struct {
    int iters;
    int capped;      /* hit max_iters */
    int timed_out;   /* stopped at the deadline */
    int indefinite;  /* stopped at non-positive curvature p^T A p <= 0 (x: the last
                        iterate, or P(b) when it happened in the first iteration) */
    double rho0, rho;
} PcgResult;

/* Work arrays are kept inside and reused (allocate once per size). */
typedef struct {
    int cap_nodes;
    double *r, *z, *p, *q;
} PcgWork;

int pcg_solve(const LinearOp *A, InvApprox *M, const Projection *proj, const double *b, double *x,
              const PcgOptions *opt, PcgWork *work, PcgResult *res);
void pcg_work_free(PcgWork *w);
/* z = P(M^-1 r) over len entries (M == NULL: the identity), the
 * preconditioning step of pcg_solve and minres_solve. */
int precondition_projected(InvApprox *M, const Projection *proj, size_t len, const double *r, double *z);

#endif
