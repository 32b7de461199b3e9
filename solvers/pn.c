/* Projected Newton (SPEC 5; HOT §5, reference §4): at every iterate the
 * projected (SPD) Hessian is rebuilt, H p = -g is solved inexactly by PCG
 * with the forcing term eta = min(0.5, sqrt(max(rho0, tau))), and a
 * backtracking line search takes the step. Stops by the CN rule. */
#include <omp.h>
#include <string.h>

#include "core/error.h"
#include "core/linesearch.h"
#include "core/vec.h"
#include "solvers/solver.h"

int pn_solve(Solver *s, StepProblem *pb, const SolveSettings *set, double *dv, SolveStats *st, IterHook hook,
             void *hook_ctx)
{
    int status;
    int n = pb->n_nodes;
    size_t len = 3 * (size_t)n;
    int assembled = !s->preset->matrix_free;
    double t_start = omp_get_wtime();
    double E = problem_energy(pb, dv);
    st->ls_evals++;
    problem_gradient(pb, dv, s->g);
    double tau = problem_tau(pb, set->eps);
    LinearOp op;
    Projection proj;
    solver_hessian_op(s, pb, assembled, &op);
    solver_projection(pb, &proj);
    LineSearchOptions lso = {set->armijo, set->max_halvings};
    for (int it = 0;; ++it) {
        if (solver_should_stop(pb, set, s->g, E, it, t_start, hook, hook_ctx, st)) break;
        st->outer_iters++;

        double t0 = omp_get_wtime();
        if ((status = problem_tangent(pb, 1))) return status;
        if (assembled && (status = problem_assemble(pb, &s->H))) return status;
        double t1 = omp_get_wtime();
        if ((status = solver_setup_inverse(s, pb, assembled, &op, &proj))) return status;
        double t2 = omp_get_wtime();
        /* solve H p = -g */
        vec_copy(len, s->g, s->g_new);
        vec_scale(len, -1.0, s->g_new);
        PcgOptions po = {PCG_FORCING, tau, 0.0, set->max_linear};
        PcgResult pr;
        if ((status = pcg_solve(&op, s->inv, &proj, s->g_new, s->p, &po, &s->pcg, &pr))) return status;
        st->linear_iters += pr.iters;
        double t3 = omp_get_wtime();
        st->assemble_s += t1 - t0;
        st->setup_s += t2 - t1;
        st->solve_s += t3 - t2;

        double gTp = vec_dot(len, s->g, s->p);
        if (!(gTp < 0.0)) {
            /* not a descent direction (round-off or a capped solve): fall back
             * to steepest descent rather than stall */
            vec_copy(len, s->g, s->p);
            vec_scale(len, -1.0, s->p);
            gTp = -vec_dot(len, s->g, s->g);
        }
        LineSearchResult lr;
        if ((status = linesearch_backtrack(pb, dv, s->p, E, gTp, &lso, s->dv_new, &lr))) return status;
        st->ls_evals += lr.evals;
        st->linesearch_s += omp_get_wtime() - t3;
        if (lr.stalled) {
            st->status = SOLVE_STALLED;
            problem_gradient(pb, dv, s->g);
            st->residual = problem_cn_residual(pb, s->g);
            break;
        }
        vec_copy(len, s->dv_new, dv);
        E = lr.energy;
        problem_gradient(pb, dv, s->g);
    }
    if (assembled) {
        st->hessian_blocks = s->H.nnzb;
        st->hessian_bytes = bsr_bytes(&s->H);
    }
    return MPM_OK;
}
