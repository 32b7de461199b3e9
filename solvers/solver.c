#include "solvers/solver.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

const char *solve_status_name(SolveStatus s)
{
    switch (s) {
    case SOLVE_CONVERGED: return "converged";
    case SOLVE_CAPPED: return "capped";
    case SOLVE_STALLED: return "stalled";
    default: return "failed";
    }
}

void solve_settings_default(SolveSettings *s)
{
    s->eps = 1e-7;
    s->max_outer = 10000;
    s->max_linear = 10000;
    s->armijo = 0;
    s->max_halvings = 60;
}

int solver_create(const SolverPreset *preset, const SolverOptions *opts, Solver **out)
{
    Solver *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory creating solver %s", preset->name);
    s->preset = preset;
    if (opts) s->opts = *opts;
    int status = MPM_OK;
    s->window = 8;
    if (preset->method == METHOD_LBFGS) {
        s->window = (int)solver_opt_number(&s->opts, "window", 8, &status);
        if (status) {
            free(s);
            return status;
        }
        if (s->window < 1 || s->window > 64) {
            int w = s->window;
            free(s);
            return mpm_error(MPM_EINPUT, "--solver-opt window=%d: expected 1..64", w);
        }
    }
    if (preset->inv && (status = preset->inv->create(&s->opts, &s->inv))) {
        free(s);
        return status;
    }
    if ((status = solver_opts_check_used(&s->opts, preset->name))) {
        solver_destroy(s);
        return status;
    }
    *out = s;
    return MPM_OK;
}

int solver_should_stop(StepProblem *pb, const SolveSettings *set, const double *g, double E, int it, double t_start,
                       IterHook hook, void *hook_ctx, SolveStats *st)
{
    double res = problem_cn_residual(pb, g);
    st->residual = res;
    if (hook) hook(hook_ctx, it, omp_get_wtime() - t_start, res, E);
    if (!isfinite(res) || !isfinite(E)) {
        st->status = SOLVE_FAILED;
        return 1;
    }
    if (res < set->eps) {
        st->status = SOLVE_CONVERGED;
        return 1;
    }
    if (it >= set->max_outer) {
        st->status = SOLVE_CAPPED;
        return 1;
    }
    return 0;
}

int solver_reserve(Solver *s, int n)
{
    if (n <= s->cap_nodes) return MPM_OK;
    int cap = n + n / 4 + 256;
    size_t v = sizeof(double) * 3 * (size_t)cap;
    double **vecs[] = {&s->g, &s->p, &s->dv_new, &s->g_new};
    for (size_t k = 0; k < sizeof vecs / sizeof vecs[0]; ++k) {
        double *q = realloc(*vecs[k], v);
        if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: solver vectors (%d nodes)", n);
        *vecs[k] = q;
    }
    double *d = realloc(s->diag, 3 * v);
    if (!d) return mpm_error(MPM_EINTERNAL, "out of memory: solver diagonal");
    s->diag = d;
    if (s->preset->method == METHOD_LBFGS) {
        size_t hist = v * (size_t)s->window;
        double *S = realloc(s->S, hist), *Y = S ? realloc(s->Y, hist) : NULL;
        if (!S || !Y) return mpm_error(MPM_EINTERNAL, "out of memory: L-BFGS history");
        s->S = S;
        s->Y = Y;
        if (!s->rho_hist) {
            s->rho_hist = calloc((size_t)s->window, sizeof(double));
            s->xi = calloc((size_t)s->window, sizeof(double));
            if (!s->rho_hist || !s->xi) return mpm_error(MPM_EINTERNAL, "out of memory: L-BFGS history");
        }
    }
    s->cap_nodes = cap;
    return MPM_OK;
}

static void apply_assembled(const void *ctx, const double *x, double *y) { bsr_spmv((const Bsr *)ctx, x, y); }

static void apply_matrix_free(const void *ctx, const double *x, double *y)
{
    problem_hessvec((StepProblem *)ctx, x, y);
}

static void apply_projection(const void *ctx, double *v) { problem_project((const StepProblem *)ctx, v); }

void solver_hessian_op(Solver *s, StepProblem *pb, int assembled, LinearOp *op)
{
    op->n_nodes = pb->n_nodes;
    op->apply = assembled ? apply_assembled : apply_matrix_free;
    op->ctx = assembled ? (const void *)&s->H : (const void *)pb;
}

void solver_projection(StepProblem *pb, Projection *P)
{
    P->apply = pb->n_dirichlet ? apply_projection : NULL;
    P->ctx = pb;
}

int solver_setup_inverse(Solver *s, StepProblem *pb, int assembled, LinearOp *op, Projection *proj)
{
    if (assembled) bsr_diagonal(&s->H, s->diag);
    else problem_diagonal(pb, s->diag);
    if (!s->inv) return MPM_OK;
    InvSetupInput in = {
        .n_nodes = pb->n_nodes,
        .H = assembled ? &s->H : NULL,
        .diag = s->diag,
        .coord = pb->grid->coord,
        .coloring = &pb->grid->coloring,
        .op = op,
        .proj = proj,
        .problem = pb,
    };
    return s->inv->ops->setup(s->inv, &in);
}

int solver_solve(Solver *s, StepProblem *pb, const SolveSettings *set, double *dv, SolveStats *st, IterHook hook,
                 void *hook_ctx)
{
    memset(st, 0, sizeof *st);
    int status = solver_reserve(s, pb->n_nodes);
    if (status) return status;
    switch (s->preset->method) {
    case METHOD_PN: return pn_solve(s, pb, set, dv, st, hook, hook_ctx);
    case METHOD_LBFGS: return lbfgs_solve(s, pb, set, dv, st, hook, hook_ctx);
    default: return mpm_error(MPM_EINTERNAL, "solver %s: outer method not available", s->preset->name);
    }
}

void solver_destroy(Solver *s)
{
    if (!s) return;
    if (s->inv) s->inv->ops->destroy(s->inv);
    bsr_free(&s->H);
    pcg_work_free(&s->pcg);
    free(s->g);
    free(s->p);
    free(s->dv_new);
    free(s->g_new);
    free(s->diag);
    free(s->S);
    free(s->Y);
    free(s->rho_hist);
    free(s->xi);
    free(s);
}
