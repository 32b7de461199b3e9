/* Preconditioned conjugate gradients from x = 0 (SPEC 5; HOT reference §4
 * step 5 and §5.3).
 *
 *   x = 0;  r = P(b);  z = P(M^-1 r);  p = z;  rho0 = sqrt(r^T z)
 *   loop (check at the top):
 *     stop if sqrt(r^T z) < threshold         (forcing term, absolute, relative;
 *                                              PCG_RELATIVE_L2 compares ||r||_2)
 *     stop if max_iters iterations were done  (capped = 1)
 *     q = P(A p);  alpha = r^T z / p^T q
 *     stop if p^T q <= 0                      (non-positive curvature)
 *     x += alpha p;  r -= alpha q;  z = P(M^-1 r)
 *     beta = r^T z_new / r^T z_old;  p = z + beta p
 *
 * A preconditioner that is not a fixed linear map (M->flexible: a V-cycle
 * whose coarsest PCG stops adaptively) breaks the conjugacy plain PCG relies
 * on; with a poor coarse operator (rediscretised GMG) plain PCG then needs
 * thousands of iterations. For those, beta takes the Polak-Ribiere form
 * beta = z_new^T (r_new - r_old) / r_old^T z_old = -alpha z_new^T q / r_old^T z_old
 * of flexible CG (Notay 2000, "Flexible conjugate gradients", SIAM J. Sci.
 * Comput. 22(4)), which equals the plain beta in exact arithmetic when M is
 * fixed and SPD.
 *
 * Non-positive curvature (PcgResult.indefinite): following Gast et al.
 * 2015 §3.1 ("if indefiniteness is encountered during the conjugate gradient
 * solve, return the last iterate computed; if this occurs on the first step,
 * return the right hand side"), x is then the last iterate, or P(b) when it
 * happens in the first iteration, so the result is always a descent direction
 * for the quadratic model. With a projected (SPD) Hessian this never happens
 * except at breakdown. All reductions go through vec_dot, so results are
 * deterministic for a fixed thread count. */
#include "solvers/krylov/pcg.h"

#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/vec.h"

static int pcg_work_reserve(PcgWork *w, int n)
{
    if (n <= w->cap_nodes && w->r) return MPM_OK;
    if (n < 1) n = 1;
    size_t len = 3 * (size_t)n;
    double **arr[4] = {&w->r, &w->z, &w->p, &w->q};
    for (int k = 0; k < 4; ++k) {
        double *a = realloc(*arr[k], sizeof(double) * len);
        if (!a) return mpm_error(MPM_EINTERNAL, "out of memory: PCG work vectors (%d nodes)", n);
        *arr[k] = a;
    }
    w->cap_nodes = n;
    return MPM_OK;
}

void pcg_work_free(PcgWork *w)
{
    if (!w) return;
    free(w->r);
    free(w->z);
    free(w->p);
    free(w->q);
    w->r = w->z = w->p = w->q = NULL;
    w->cap_nodes = 0;
}

int precondition_projected(InvApprox *M, const Projection *proj, size_t len, const double *r, double *z)
{
    if (M) {
        int st = inv_apply(M, r, z);
        if (st) return st;
    } else {
        vec_copy(len, r, z);
    }
    projection_apply(proj, z);
    return MPM_OK;
}

int pcg_solve(const LinearOp *A, InvApprox *M, const Projection *proj, const double *b, double *x,
              const PcgOptions *opt, PcgWork *work, PcgResult *res)
{
    res->iters = 0;
    res->capped = 0;
    res->timed_out = 0;
    res->indefinite = 0;
    res->rho0 = res->rho = 0.0;
    const int n = A->n_nodes;
    const size_t len = 3 * (size_t)n;
    int st = pcg_work_reserve(work, n);
    if (st) return st;
    double *r = work->r, *z = work->z, *p = work->p, *q = work->q;
    const int flexible = M && M->flexible;

    vec_zero(len, x);
    vec_copy(len, b, r);
    projection_apply(proj, r);
    st = precondition_projected(M, proj, len, r, z);
    if (st) return st;
    double rz = vec_dot(len, r, z);
    if (!isfinite(rz)) return mpm_error(MPM_ENUMERIC, "pcg: non-finite initial residual (r^T M^-1 r = %g)", rz);
    if (rz < 0.0)
        return mpm_error(MPM_ENUMERIC, "pcg: preconditioner is not positive definite (r^T M^-1 r = %g)", rz);
    const double rho0 = sqrt(rz);
    res->rho0 = res->rho = rho0;
    if (rz == 0.0) return MPM_OK; /* b is zero in the free subspace: x = 0 is exact */

    /* the stopping test compares `measure` (the preconditioned norm rho, or
     * the plain ||r||_2 for PCG_RELATIVE_L2) with `threshold` */
    const int l2 = opt->stop == PCG_RELATIVE_L2;
    double threshold;
    if (opt->stop == PCG_FORCING) {
        double eta = fmin(0.5, sqrt(fmax(rho0, opt->tau)));
        threshold = eta * rho0;
    } else if (opt->stop == PCG_ABSOLUTE) {
        threshold = opt->abs_tol;
    } else if (opt->stop == PCG_RELATIVE) {
        threshold = opt->rel_tol * rho0;
    } else {
        threshold = opt->rel_tol * vec_norm(len, r);
    }

    vec_copy(len, z, p);
    double rho = rho0;
    double measure = l2 ? vec_norm(len, r) : rho0;
    int it = 0;
    for (;;) {
        if (measure < threshold) break;
        if (it >= opt->max_iters) {
            res->capped = 1;
            break;
        }
        if (deadline_passed(&opt->deadline)) {
            res->timed_out = 1;
            break;
        }
        A->apply(A->ctx, p, q);
        projection_apply(proj, q);
        double pq = vec_dot(len, p, q);
        if (!(pq > 0.0)) { /* also catches NaN */
            if (it == 0) vec_copy(len, r, x);
            res->indefinite = 1;
            break;
        }
        double alpha = rz / pq;
        vec_axpy(len, alpha, p, x);
        vec_axpy(len, -alpha, q, r);
        st = precondition_projected(M, proj, len, r, z);
        if (st) return st;
        double rz_new = vec_dot(len, r, z);
        ++it;
        if (!isfinite(rz_new) || rz_new < 0.0) {
            res->iters = it;
            return mpm_error(MPM_ENUMERIC, "pcg: r^T M^-1 r = %g at iteration %d (preconditioner not SPD?)", rz_new,
                             it);
        }
        double beta = rz_new / rz;
        if (flexible) beta = -alpha * vec_dot(len, z, q) / rz;
        vec_xpby(len, z, beta, p);
        rz = rz_new;
        rho = sqrt(rz);
        measure = l2 ? vec_norm(len, r) : rho;
        if (rz == 0.0) break; /* exact solution reached */
    }
    res->iters = it;
    res->rho = rho;
    return MPM_OK;
}
