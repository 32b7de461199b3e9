/* L-BFGS with a problem-specific initial inverse Hessian (SPEC 7; HOT §4,
 * Algorithm 3; reference §6). At iteration 0 of every step the BC-projected
 * Hessian is built at dv^0 and the inverse approximation (a multigrid
 * V-cycle for HOT, an inexact PCG for LBFGS-H, ...) is set up on it; the
 * two-loop recursion applies it to q with no gamma scaling, the result is
 * projected, a backtracking line search takes the step, and the pair
 * (s, y = g_new - g_old) is kept only if y^T s > 0. Stops by the CN rule. */
#include <math.h>
#include <omp.h>
#include <string.h>

#include "core/error.h"
#include "core/linesearch.h"
#include "core/vec.h"
#include "solvers/solver.h"

int lbfgs_solve(Solver *s, StepProblem *pb, const SolveSettings *set, double *dv, SolveStats *st, IterHook hook,
                void *hook_ctx)
{
    int status;
    size_t len = 3 * (size_t)pb->n_nodes;
    double t_start = omp_get_wtime();
    double E = problem_energy(pb, dv);
    st->ls_evals++;
    problem_gradient(pb, dv, s->g);
    LinearOp op;
    Projection proj;
    solver_hessian_op(s, pb, 1, &op);
    solver_projection(pb, &proj);
    LineSearchOptions lso = {set->armijo, set->max_halvings};
    int m = s->window, count = 0, head = 0; /* ring buffer of the newest `count` pairs; head = next slot */
    long inner_before = 0;
    for (int it = 0;; ++it) {
        if (solver_should_stop(pb, set, s->g, E, it, t_start, hook, hook_ctx, st)) break;
        st->outer_iters++;
        if (it == 0) {
            /* the Hessian and its inverse approximation, once per step, lagged at dv^0 */
            double t0 = omp_get_wtime();
            if ((status = problem_tangent(pb, 1))) return status;
            if ((status = problem_assemble(pb, &s->H))) return status;
            double t1 = omp_get_wtime();
            if ((status = solver_setup_inverse(s, pb, 1, &op, &proj))) return status;
            st->assemble_s += t1 - t0;
            st->setup_s += omp_get_wtime() - t1;
            inner_before = s->inv ? s->inv->stats.inner_iters : 0;
            count = head = 0;
        }
        double t2 = omp_get_wtime();
        /* two-loop recursion on q = -g */
        double *q = s->g_new, *d = s->p;
        for (size_t k = 0; k < len; ++k) q[k] = -s->g[k];
        for (int c = 0; c < count; ++c) {
            int i = (head - 1 - c + m) % m;
            double *Si = s->S + len * (size_t)i, *Yi = s->Y + len * (size_t)i;
            s->xi[i] = s->rho_hist[i] * vec_dot(len, Si, q);
            vec_axpy(len, -s->xi[i], Yi, q);
        }
        if (s->inv) {
            if ((status = s->inv->ops->apply(s->inv, q, d))) return status;
        } else {
            vec_copy(len, q, d);
        }
        problem_project(pb, d);
        for (int c = count - 1; c >= 0; --c) {
            int i = (head - 1 - c + m) % m;
            double *Si = s->S + len * (size_t)i, *Yi = s->Y + len * (size_t)i;
            double beta = s->rho_hist[i] * vec_dot(len, Yi, d);
            vec_axpy(len, s->xi[i] - beta, Si, d);
        }
        double gTd = vec_dot(len, s->g, d);
        if (!(gTd < 0.0)) {
            vec_copy(len, s->g, d);
            vec_scale(len, -1.0, d);
            gTd = -vec_dot(len, s->g, s->g);
        }
        double t3 = omp_get_wtime();
        st->solve_s += t3 - t2;
        LineSearchResult lr;
        if ((status = linesearch_backtrack(pb, dv, d, E, gTd, &lso, s->dv_new, &lr))) return status;
        st->ls_evals += lr.evals;
        if (lr.stalled) {
            st->linesearch_s += omp_get_wtime() - t3;
            st->status = SOLVE_STALLED;
            problem_gradient(pb, dv, s->g);
            st->residual = problem_cn_residual(pb, s->g);
            break;
        }
        problem_gradient(pb, s->dv_new, s->g_new);
        st->linesearch_s += omp_get_wtime() - t3;
        /* new pair s = dv_new - dv, y = g_new - g (stored in the head slot) */
        double *Sn = s->S + len * (size_t)head, *Yn = s->Y + len * (size_t)head;
        for (size_t k = 0; k < len; ++k) {
            Sn[k] = s->dv_new[k] - dv[k];
            Yn[k] = s->g_new[k] - s->g[k];
        }
        double ys = vec_dot(len, Yn, Sn);
        if (ys > 0.0 && isfinite(ys)) {
            s->rho_hist[head] = 1.0 / ys;
            head = (head + 1) % m;
            if (count < m) ++count;
        }
        vec_copy(len, s->dv_new, dv);
        vec_copy(len, s->g_new, s->g);
        E = lr.energy;
    }
    if (s->inv) st->linear_iters += s->inv->stats.inner_iters - inner_before;
    st->hessian_blocks = s->H.nnzb;
    st->hessian_bytes = bsr_bytes(&s->H);
    return MPM_OK;
}
