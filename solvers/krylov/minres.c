/* Preconditioned MINRES (see minres.h). With z_j the M-normalised Lanczos
 * vectors of the preconditioned operator and Givens rotations (c, s) that
 * reduce the tridiagonal T_j to upper triangular form:
 *
 *   v_1 = P b;  z_1 = P M^-1 v_1;  gamma_1 = sqrt(v_1^T z_1);  eta = gamma_1
 *   loop j = 1, 2, ...  (stop at the top when |eta| < rel_tol gamma_1)
 *     z_j /= gamma_j;  q = P A z_j;  delta_j = q^T z_j
 *     v_{j+1} = q - (delta_j / gamma_j) v_j - (gamma_j / gamma_{j-1}) v_{j-1}
 *     z_{j+1} = P M^-1 v_{j+1};  gamma_{j+1} = sqrt(v_{j+1}^T z_{j+1})
 *     a0 = c_j delta_j - c_{j-1} s_j gamma_j;   a1 = sqrt(a0^2 + gamma_{j+1}^2)
 *     a2 = s_j delta_j + c_{j-1} c_j gamma_j;   a3 = s_{j-1} gamma_j
 *     c_{j+1} = a0 / a1;  s_{j+1} = gamma_{j+1} / a1
 *     w_{j+1} = (z_j - a3 w_{j-1} - a2 w_j) / a1
 *     x += c_{j+1} eta w_{j+1};  eta = -s_{j+1} eta      (|eta| = ||b - A x||_{M^-1})
 *
 * with gamma_0 = 1, c_0 = c_1 = 1, s_0 = s_1 = 0, w_0 = w_1 = 0. Every
 * reduction goes through vec_dot (deterministic for a fixed thread count). */
#include "solvers/krylov/minres.h"

#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/krylov/pcg.h"

static int minres_reserve(MinresWork *w, int n)
{
    if (n <= w->cap_nodes && w->v0) return MPM_OK;
    if (n < 1) n = 1;
    double **arr[7] = {&w->v0, &w->v1, &w->z, &w->zn, &w->w0, &w->w1, &w->q};
    for (int k = 0; k < 7; ++k) {
        double *a = realloc(*arr[k], sizeof(double) * 3 * (size_t)n);
        if (!a) return mpm_error(MPM_EINTERNAL, "out of memory: MINRES work vectors (%d nodes)", n);
        *arr[k] = a;
    }
    w->cap_nodes = n;
    return MPM_OK;
}

void minres_work_free(MinresWork *w)
{
    if (!w) return;
    double **arr[7] = {&w->v0, &w->v1, &w->z, &w->zn, &w->w0, &w->w1, &w->q};
    for (int k = 0; k < 7; ++k) {
        free(*arr[k]);
        *arr[k] = NULL;
    }
    w->cap_nodes = 0;
}

/* z = P(M^-1 v) and gamma = sqrt(v^T z); MPM_ENUMERIC when v^T z < 0 or not finite. */
static int precondition(InvApprox *M, const Projection *proj, size_t len, const double *v, double *z, int it,
                        double *gamma)
{
    int st = precondition_projected(M, proj, len, v, z);
    if (st) return st;
    double vz = vec_dot(len, v, z);
    if (!isfinite(vz) || vz < 0.0)
        return mpm_error(MPM_ENUMERIC, "minres: v^T M^-1 v = %g at iteration %d (preconditioner not SPD?)", vz, it);
    *gamma = sqrt(vz);
    return MPM_OK;
}

int minres_solve(const LinearOp *A, InvApprox *M, const Projection *proj, const double *b, double *x,
                 const MinresOptions *opt, MinresWork *work, MinresResult *res)
{
    res->iters = res->capped = res->timed_out = 0;
    res->res0 = res->res = 0.0;
    const int n = A->n_nodes;
    const size_t len = 3 * (size_t)n;
    int st = minres_reserve(work, n);
    if (st) return st;
    double *v_prev = work->v0, *v = work->v1, *z = work->z, *z_next = work->zn, *w_prev = work->w0, *w = work->w1,
           *q = work->q;
    vec_zero(len, x);
    vec_zero(len, v_prev);
    vec_zero(len, w_prev);
    vec_zero(len, w);
    vec_copy(len, b, v);
    projection_apply(proj, v);
    double gamma = 0.0;
    if ((st = precondition(M, proj, len, v, z, 0, &gamma))) return st;
    res->res0 = res->res = gamma;
    if (gamma == 0.0) return MPM_OK; /* b is zero in the free subspace */
    const double threshold = opt->rel_tol * gamma;
    double gamma_prev = 1.0, eta = gamma;
    double c = 1.0, c_prev = 1.0, s = 0.0, s_prev = 0.0;
    int it = 0;
    for (;;) {
        if (fabs(eta) < threshold) break;
        if (it >= opt->max_iters) {
            res->capped = 1;
            break;
        }
        if (deadline_passed(&opt->deadline)) {
            res->timed_out = 1;
            break;
        }
        vec_scale(len, 1.0 / gamma, z);
        A->apply(A->ctx, z, q);
        projection_apply(proj, q);
        double delta = vec_dot(len, q, z);
        /* v_{j+1} into v_prev's storage */
        const double f1 = delta / gamma, f0 = gamma / gamma_prev;
#pragma omp parallel for schedule(static)
        for (size_t k = 0; k < len; ++k) v_prev[k] = q[k] - f1 * v[k] - f0 * v_prev[k];
        double gamma_next = 0.0;
        ++it;
        if ((st = precondition(M, proj, len, v_prev, z_next, it, &gamma_next))) {
            res->iters = it;
            return st;
        }
        double a0 = c * delta - c_prev * s * gamma;
        double a1 = sqrt(a0 * a0 + gamma_next * gamma_next);
        double a2 = s * delta + c_prev * c * gamma;
        double a3 = s_prev * gamma;
        if (!(a1 > 0.0) || !isfinite(a1)) {
            res->iters = it;
            return mpm_error(MPM_ENUMERIC, "minres: breakdown at iteration %d (the operator is singular on the "
                                           "Krylov space, or a non-finite value)", it);
        }
        c_prev = c;
        s_prev = s;
        c = a0 / a1;
        s = gamma_next / a1;
        /* w_{j+1} into w_prev's storage */
        const double ce = c * eta;
#pragma omp parallel for schedule(static)
        for (size_t k = 0; k < len; ++k) {
            double wn = (z[k] - a3 * w_prev[k] - a2 * w[k]) / a1;
            w_prev[k] = wn;
            x[k] += ce * wn;
        }
        eta = -s * eta;
        double *t = w_prev;
        w_prev = w;
        w = t;
        t = v_prev;
        v_prev = v;
        v = t;
        t = z;
        z = z_next;
        z_next = t;
        gamma_prev = gamma;
        gamma = gamma_next;
        if (gamma == 0.0) break; /* invariant subspace: x is exact */
    }
    res->iters = it;
    res->res = fabs(eta);
    return MPM_OK;
}
