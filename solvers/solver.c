#include "solvers/solver.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

void solve_settings_default(SolveSettings *s)
{
    memset(s, 0, sizeof *s);
    s->eps = 1e-7;
    s->max_outer = 10000;
    s->max_linear = 10000;
    s->max_halvings = 60;
}

int solve_settings_check(const SolveSettings *s)
{
    if (!(s->eps > 0.0) || !isfinite(s->eps))
        return mpm_error(MPM_EINPUT, "--eps %g: expected a positive number", s->eps);
    if (s->eps < SOLVE_EPS_MIN)
        return mpm_error(MPM_EINPUT,
                         "--eps %g: below %.3g, the smallest CN residual double precision resolves (DBL_EPSILON / 24)",
                         s->eps, SOLVE_EPS_MIN);
    if (s->max_outer < 1) return mpm_error(MPM_EINPUT, "--max-outer %d: expected >= 1", s->max_outer);
    if (s->max_linear < 1) return mpm_error(MPM_EINPUT, "--max-linear %d: expected >= 1", s->max_linear);
    if (s->max_halvings < 0) return mpm_error(MPM_EINPUT, "max_halvings %d: expected >= 0", s->max_halvings);
    return MPM_OK;
}

int solver_create(const char *name, const OuterMethodOps *outer, const InvApproxOps *inverse, const SolverOptions *opts,
                  Solver **out)
{
    *out = NULL;
    Solver *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory creating solver %s", name);
    snprintf(s->name, sizeof s->name, "%s", name);
    if (opts) s->opts = *opts;
    int st = MPM_OK;
    const char *ls = solver_opt_string(&s->opts, "linesearch", "halving");
    const char *stop = solver_opt_string(&s->opts, "stop", "cn");
    s->stall_iters = solver_opt_int(&s->opts, "stall_iters", 20, 1, 1000000, &st);
    if (!st && !(s->ls = line_search_find(ls)))
        st = mpm_error(MPM_EINPUT, "solver option linesearch=%s: unknown line search (see: mpmbench list solvers)", ls);
    if (!st && !(s->stop = stop_rule_find(stop)))
        st = mpm_error(MPM_EINPUT, "solver option stop=%s: unknown stopping rule (see: mpmbench list solvers)", stop);
    s->stop_tol = NAN;
    if (!st && s->stop->tol_key) {
        s->stop_tol = solver_opt_number(&s->opts, s->stop->tol_key, s->stop->tol_default, &st);
        if (!st && !(s->stop_tol > 0.0))
            st = mpm_error(MPM_EINPUT, "solver option %s=%g: expected a positive number", s->stop->tol_key, s->stop_tol);
    }
    if (!st) st = outer->create(&s->opts, &s->outer);
    if (!st) s->outer->ops = outer;
    if (!st) st = inv_create(inverse, &s->opts, &s->inv);
    if (!st && (s->inv->caps & INV_NEEDS_MATRIX) && !s->outer->assembled)
        st = mpm_error(MPM_EINPUT,
                       "solver %s: inverse approximation '%s' needs the assembled Hessian, which outer method '%s' "
                       "does not build (matrix-free)",
                       name, inverse->name, outer->name);
    if (!st) st = solver_opts_check_used(&s->opts, name);
    if (st) {
        solver_destroy(s);
        return st;
    }
    *out = s;
    return MPM_OK;
}

int solver_solve(Solver *s, StepProblem *pb, const SolveSettings *set, double *dv, SolveStats *st, IterHook hook,
                 void *hook_ctx)
{
    memset(st, 0, sizeof *st);
    SolveCtx c = {
        .pb = pb,
        .inv = s->inv,
        .ls = s->ls,
        .stop = s->stop,
        .stop_tol = isnan(s->stop_tol) ? set->eps : s->stop_tol,
        .stall_iters = s->stall_iters,
        .set = set,
        .hook = hook,
        .hook_ctx = hook_ctx,
        .t_start = omp_get_wtime(),
        .best_energy = INFINITY,
        .best_residual = INFINITY,
    };
    long inner0 = inv_inner_iters(s->inv);
    inv_begin_solve(s->inv);
    int status = s->outer->ops->solve(s->outer, &c, dv, st);
    st->inner_iters = inv_inner_iters(s->inv) - inner0;
    /* the direction (Krylov solves, two-loop recursion) and the stopping
     * tests: what the timed phases of the wrappers did not cover */
    double rest = omp_get_wtime() - c.t_start - st->assemble_s - st->setup_s - st->linesearch_s;
    st->solve_s = rest > 0.0 ? rest : 0.0;
    if (status == MPM_ENUMERIC) {
        /* a breakdown of this step, not of the program: the step's status */
        st->status = SOLVE_FAILED;
        snprintf(st->reason, sizeof st->reason, "%s", mpm_last_error());
        mpm_clear_error();
        status = MPM_OK;
    }
    return status;
}

void solver_view(const Solver *s, FILE *f, InvView *inv_view_out)
{
    if (f) {
        fprintf(f, "solver %s: outer method %s x inverse approximation %s; line search %s; stop %s", s->name,
                s->outer->ops->name, s->inv->ops->name, s->ls->name, s->stop->name);
        if (!isnan(s->stop_tol)) fprintf(f, " (%s = %g)", s->stop->tol_key, s->stop_tol);
        fprintf(f, "; stalled after %d iterations without progress\n", s->stall_iters);
        if (s->outer->ops->view) s->outer->ops->view(s->outer, f);
    }
    inv_view(s->inv, f, inv_view_out);
}

void solver_destroy(Solver *s)
{
    if (!s) return;
    if (s->outer) s->outer->ops->destroy(s->outer);
    inv_destroy(s->inv);
    free(s);
}
