/* What every outer method shares (see outer_method.h): the stopping test,
 * the timed phases, the operators. */
#include "solvers/outer_method.h"

#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"

const char *solve_status_name(SolveStatus s)
{
    switch (s) {
    case SOLVE_CONVERGED: return "converged";
    case SOLVE_CAPPED: return "capped";
    case SOLVE_STALLED: return "stalled";
    case SOLVE_TIMEOUT: return "timeout";
    default: return "failed";
    }
}

int solve_end(SolveStats *st, SolveStatus status, const char *fmt, ...)
{
    st->status = status;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(st->reason, sizeof st->reason, fmt, ap);
    va_end(ap);
    return 1;
}

int solve_past_deadline(const SolveCtx *c) { return deadline_passed(&c->set->deadline); }

void solve_report_iteration(SolveCtx *c, int it, double residual, double E)
{
    if (c->hook) c->hook(c->hook_ctx, it, event_log_elapsed(c->log, c->phase[STEP_SOLVE]), residual, E);
}

/* solve_energy and solve_gradient return no status: a refused begin or end
 * stays in the log, and solver_solve reports it from its snapshot. */
double solve_energy(SolveCtx *c, const double *dv, SolveStats *st)
{
    event_log_begin(c->log, c->phase[STEP_LINESEARCH]);
    double E = problem_energy(c->pb, dv);
    st->ls_evals++;
    event_log_end(c->log, c->phase[STEP_LINESEARCH]);
    return E;
}

void solve_gradient(SolveCtx *c, const double *dv, double *g, SolveStats *st)
{
    event_log_begin(c->log, c->phase[STEP_LINESEARCH]);
    problem_gradient(c->pb, dv, g);
    event_log_end(c->log, c->phase[STEP_LINESEARCH]);
}

double solve_evaluate(SolveCtx *c, const double *dv, double *g, SolveStats *st)
{
    double E = solve_energy(c, dv, st);
    solve_gradient(c, dv, g, st);
    return E;
}

int solve_pcg(SolveCtx *c, const LinearOp *op, const Projection *proj, const double *b, double *x,
              const PcgOptions *opt, PcgWork *work, PcgResult *res, SolveStats *st)
{
    int status = pcg_solve(op, c->inv, proj, b, x, opt, work, res);
    st->linear_iters += res->iters;
    return status;
}

int solve_minres(SolveCtx *c, const LinearOp *op, const Projection *proj, const double *b, double *x,
                 const MinresOptions *opt, MinresWork *work, MinresResult *res, SolveStats *st)
{
    int status = minres_solve(op, c->inv, proj, b, x, opt, work, res);
    st->linear_iters += res->iters;
    return status;
}

int solve_should_stop(SolveCtx *c, const double *g, double E, int it, SolveStats *st)
{
    double res = problem_cn_residual(c->pb, g);
    st->residual = res;
    if (it == 0) c->energy0 = E;
    solve_report_iteration(c, it, res, E);
    if (!isfinite(res) || !isfinite(E))
        return solve_end(st, SOLVE_FAILED, "non-finite %s (%g) at outer iteration %d", isfinite(E) ? "residual" : "energy",
                         isfinite(E) ? res : E, it);
    if (c->stop->measure(c->pb, g, res) < c->stop_tol) {
        st->status = SOLVE_CONVERGED;
        st->reason[0] = '\0';
        return 1;
    }
    if (it >= c->set->max_outer) return solve_end(st, SOLVE_CAPPED, "outer iteration cap %d reached", c->set->max_outer);
    if (deadline_passed(&c->set->deadline))
        return solve_end(st, SOLVE_TIMEOUT, "time limit %s reached after %d outer iterations",
                         deadline_reason(&c->set->deadline), it);
    int progress = 0;
    if (E < c->best_energy) c->best_energy = E, progress = 1;
    if (res < c->best_residual) c->best_residual = res, progress = 1;
    if (progress) c->last_progress = it;
    else if (it - c->last_progress >= c->stall_iters)
        return solve_end(st, SOLVE_STALLED, "no decrease of the energy or the residual in %d outer iterations",
                         c->stall_iters);
    return 0;
}

int solve_direction_converged(SolveCtx *c, double gTp, double E, SolveStats *st)
{
    if (!(c->stop->direction_measure(gTp, c->energy0, E) < c->stop_tol)) return 0;
    st->status = SOLVE_CONVERGED;
    st->reason[0] = '\0';
    return 1;
}

static void apply_assembled(const void *ctx, const double *x, double *y)
{
    const AssembledHessian *a = ctx;
    problem_assembled_product(a->pb, a->H, x, y);
}

static void apply_matrix_free(const void *ctx, const double *x, double *y)
{
    problem_hessvec((StepProblem *)ctx, x, y);
}

static void apply_projection(const void *ctx, double *v) { problem_project((const StepProblem *)ctx, v); }

void solve_hessian_op(SolveCtx *c, const Bsr *H, LinearOp *op)
{
    op->n_nodes = c->pb->n_nodes;
    c->assembled = (AssembledHessian){c->pb, H};
    op->apply = H ? apply_assembled : apply_matrix_free;
    op->ctx = H ? (const void *)&c->assembled : (const void *)c->pb;
}

void solve_projection(SolveCtx *c, Projection *P)
{
    P->apply = c->pb->n_dirichlet ? apply_projection : NULL;
    P->ctx = c->pb;
}

static int assemble(SolveCtx *c, int projected, Bsr *H, double *diag)
{
    int status = event_log_begin(c->log, c->phase[STEP_ASSEMBLE]);
    if (status) return status;
    /* Assembled: the tangent is used once, by the assembly, unless the
     * inverse rediscretises from the particles' stored tangents (GMG). */
    if (H && !(c->inv->caps & INV_NEEDS_PROBLEM)) status = problem_assemble_fused(c->pb, projected, H);
    else if (!(status = problem_tangent(c->pb, projected)) && H) status = problem_assemble(c->pb, H);
    if (!status) {
        if (H) problem_assembled_diagonal(c->pb, H, diag);
        else problem_diagonal(c->pb, diag);
    }
    return event_log_end_with(c->log, c->phase[STEP_ASSEMBLE], status);
}

int solve_assemble(SolveCtx *c, Bsr *H, double *diag, SolveStats *st) { return assemble(c, 1, H, diag); }

int solve_assemble_unprojected(SolveCtx *c, Bsr *H, double *diag, SolveStats *st)
{
    return assemble(c, 0, H, diag);
}

double solve_gradient_tolerance(const SolveCtx *c) { return c->stop->gradient_tolerance(c->pb, c->stop_tol); }

int solve_setup_inverse(SolveCtx *c, const Bsr *H, const double *diag, const LinearOp *op, const Projection *proj,
                        SolveStats *st)
{
    StepProblem *pb = c->pb;
    if (pb->comm && !(c->inv->caps & INV_DISTRIBUTED))
        return mpm_error(MPM_EINPUT, "inverse approximation %s has no form across ranks yet%s (docs/distributed.md)",
                         c->inv->ops->name,
                         !strcmp(c->inv->ops->name, "mg") ? "; HOT's across ranks is the preset hot-petsc" : "");
    InvSetupInput in = {
        .n_nodes = pb->n_nodes,
        .H = H,
        .diag = diag,
        .coord = pb->grid->coord,
        .coloring = &pb->grid->coloring,
        .op = op,
        .proj = proj,
        .problem = pb,
        .deadline = c->set->deadline,
        .comm = pb->comm,
        .owned = pb->owned,
        .decomp = pb->decomp,
    };
    return inv_setup(c->inv, &in);
}

int solve_line_search(SolveCtx *c, const double *dv, const double *g, const double *p, double E0, double gTp,
                      double *dv_new, double *g_new, LineSearchOutcome *out, SolveStats *st)
{
    int status = event_log_begin(c->log, c->phase[STEP_LINESEARCH]);
    if (status) return status;
    LineSearchParams prm = {c->set->max_halvings};
    status = c->ls->search(c->pb, dv, p, E0, g, gTp, &prm, dv_new, g_new, out);
    st->ls_evals += out->evals;
    if (!status && !out->stalled && out->energy - E0 > st->energy_increase_max)
        st->energy_increase_max = out->energy - E0; /* NaN never enters: a NaN energy fails the next stop test */
    if (!status && out->stalled) solve_end(st, SOLVE_STALLED, "%s", out->why);
    else if (!status && !out->have_gradient) problem_gradient(c->pb, dv_new, g_new);
    return event_log_end_with(c->log, c->phase[STEP_LINESEARCH], status);
}

int solve_take_step(SolveCtx *c, double *dv, double **g, double **g_new, const double *p, double *E, double gTp,
                    double *dv_new, SolveStats *st, int *stalled)
{
    LineSearchOutcome lr;
    int status = solve_line_search(c, dv, *g, p, *E, gTp, dv_new, *g_new, &lr, st);
    *stalled = status == MPM_OK && lr.stalled;
    if (status || lr.stalled) return status;
    vec_copy(3 * (size_t)c->pb->n_nodes, dv_new, dv);
    double *t = *g;
    *g = *g_new;
    *g_new = t;
    *E = lr.energy;
    return MPM_OK;
}

void solve_hessian_stats(const Bsr *H, SolveStats *st)
{
    if (!H) return;
    st->hessian_blocks = H->nnzb;
    st->hessian_bytes = bsr_bytes(H);
}

void solve_keep_dirichlet(const StepProblem *pb, const double *dv, const double *free_part, double *out, double *tmp)
{
    const size_t len = 3 * (size_t)pb->n_nodes;
    vec_copy(len, dv, tmp);
    problem_project(pb, tmp);
    if (out != free_part) vec_copy(len, free_part, out);
    problem_project(pb, out);
    vec_axpy(len, -1.0, tmp, out);
    vec_axpy(len, 1.0, dv, out);
}

int solve_reserve(double **const *vecs, const size_t *per_node, int count, int n, int *cap)
{
    if (n <= *cap) return MPM_OK;
    int c = n + n / 4 + 256;
    for (int k = 0; k < count; ++k) {
        double *q = realloc(*vecs[k], sizeof(double) * per_node[k] * (size_t)c);
        if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: solver work vectors (%d nodes)", n);
        *vecs[k] = q;
    }
    *cap = c;
    return MPM_OK;
}
