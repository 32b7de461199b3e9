/* The semi-implicit step of Stomakhin et al. 2013 (SIGGRAPH, "A material
 * point method for snow simulation", §4 steps 4-6 and eq. 9), the "original
 * method" Gast et al. 2015 §7.1 compare against; outer method
 * "semi-implicit".
 *
 * Stomakhin et al. compute the grid forces at the grid's current positions
 * (F_p = F_p^n), take the explicit velocity v* = v^n + dt M^-1 f^n and solve
 * the linear system (M + dt^2 K(x^n)) v^{n+1} = M v*, K the stiffness matrix
 * (the true, unprojected Hessian of the elastic energy) at x^n. In this
 * project's unknowns (E(dv) of SPEC 3, v = v^n + dv) that is exactly one
 * Newton step on E from the linearisation point dv_lin = -v^n (F = F^n):
 *     H(dv_lin) p = -g(dv_lin),   dv = dv_lin + p,
 * with H = M + dt^2 K unprojected and BC-projected like every solver's. No
 * line search, no second iteration: the nonlinearity is not iterated on, so
 * at large dt the step is what it is (Gast et al.: it needs small steps to
 * stay stable). H may be indefinite, so the system is solved by MINRES
 * (solvers/krylov/minres.c), preconditioned by the inverse approximation (which
 * must be SPD; the preset uses Gast's rest-configuration diagonal).
 *
 * Statistics (docs/solvers.md "Statistics contract"): outer_iters = 1, linear_iters = MINRES
 * iterations; the residual is the CN residual of g at the returned dv (how
 * far the linearised step is from solving the nonlinear one; it is not
 * driven below eps); status converged = MINRES reached its relative
 * tolerance, capped = it hit --max-linear, timeout = the deadline, failed =
 * a breakdown or a non-finite energy. The hook sees iteration 0 (at dv_lin)
 * and 1 (the result). Energy and gradient evaluations are timed as
 * linesearch_s, MINRES as solve_s.
 *
 * Options: linearize (xn): "xn" is Stomakhin's point dv_lin = -v^n (with the
 * Dirichlet components of the given dv), "guess" linearises at the dv handed
 * in; rtol (1e-6): MINRES stops when ||H p + g||_{M^-1} < rtol ||g||_{M^-1};
 * matrix_free (1). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/krylov/minres.h"
#include "solvers/outer_method.h"

typedef struct {
    OuterMethod base;
    int at_guess;
    double rtol;
    int cap;
    double *g, *rhs, *p, *tmp, *diag; /* 3n each, diag 9n */
    Bsr H;
    MinresWork mw;
} SemiImplicit;

extern const OuterMethodOps outer_semi_implicit;

static int si_create(SolverOptions *opt, OuterMethod **out)
{
    int st = MPM_OK;
    int matrix_free = solver_opt_int(opt, "matrix_free", 1, 0, 1, &st);
    double rtol = solver_opt_number(opt, "rtol", 1e-6, &st);
    const char *at = solver_opt_string(opt, "linearize", "xn");
    if (st) return st;
    if (!(rtol > 0.0 && rtol < 1.0)) return mpm_error(MPM_EINPUT, "solver option rtol=%g: expected 0 < rtol < 1", rtol);
    if (strcmp(at, "xn") != 0 && strcmp(at, "guess") != 0)
        return mpm_error(MPM_EINPUT, "solver option linearize=%s: expected xn or guess", at);
    SemiImplicit *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: semi-implicit");
    s->base.ops = &outer_semi_implicit;
    s->base.assembled = !matrix_free;
    s->rtol = rtol;
    s->at_guess = strcmp(at, "guess") == 0;
    *out = &s->base;
    return MPM_OK;
}

/* energy and gradient at dv, the CN residual into st and the hook */
static double evaluate(SolveCtx *c, const double *dv, double *g, int it, SolveStats *st)
{
    double E = solve_evaluate(c, dv, g, st);
    st->residual = problem_cn_residual(c->pb, g);
    solve_report_iteration(c, it, st->residual, E);
    return E;
}

static int si_solve(OuterMethod *self, SolveCtx *c, double *dv, SolveStats *st)
{
    SemiImplicit *s = (SemiImplicit *)self;
    StepProblem *pb = c->pb;
    const size_t len = 3 * (size_t)pb->n_nodes;
    double **vecs[] = {&s->g, &s->rhs, &s->p, &s->tmp, &s->diag};
    const size_t per[] = {3, 3, 3, 3, 9};
    int status = solve_reserve(vecs, per, 5, pb->n_nodes, &s->cap);
    if (status) return status;
    Bsr *H = self->assembled ? &s->H : NULL;

    if (!s->at_guess) {
        const double *vn = pb->grid->v;
        for (size_t k = 0; k < len; ++k) s->p[k] = -vn[k];
        solve_keep_dirichlet(pb, dv, s->p, s->rhs, s->tmp);
        vec_copy(len, s->rhs, dv);
    }
    double E = evaluate(c, dv, s->g, 0, st);
    if (!isfinite(E) || !isfinite(st->residual)) {
        solve_end(st, SOLVE_FAILED, "non-finite %s at the linearisation point", isfinite(E) ? "residual" : "energy");
        return MPM_OK;
    }
    if (solve_past_deadline(c)) {
        solve_end(st, SOLVE_TIMEOUT, "time limit %s reached before the linear solve",
                  deadline_reason(&c->set->deadline));
        return MPM_OK;
    }
    st->outer_iters = 1;
    LinearOp op;
    Projection proj;
    solve_hessian_op(c, H, &op);
    solve_projection(c, &proj);
    if ((status = solve_assemble_unprojected(c, H, s->diag, st))) return status;
    if ((status = solve_setup_inverse(c, H, s->diag, &op, &proj, st))) return status;

    for (size_t k = 0; k < len; ++k) s->rhs[k] = -s->g[k];
    MinresOptions mo = {.rel_tol = s->rtol, .max_iters = c->set->max_linear, .deadline = c->set->deadline};
    MinresResult mr;
    status = solve_minres(c, &op, &proj, s->rhs, s->p, &mo, &s->mw, &mr, st);
    if (status) return status;
    vec_axpy(len, 1.0, s->p, dv);

    E = evaluate(c, dv, s->g, 1, st);
    if (!isfinite(E) || !isfinite(st->residual))
        solve_end(st, SOLVE_FAILED, "non-finite %s after the linearised step", isfinite(E) ? "residual" : "energy");
    else if (mr.timed_out)
        solve_end(st, SOLVE_TIMEOUT, "time limit %s reached in MINRES after %d iterations",
                  deadline_reason(&c->set->deadline), mr.iters);
    else if (mr.capped)
        solve_end(st, SOLVE_CAPPED, "MINRES cap %d reached (relative residual %.2e, asked %.2e)", c->set->max_linear,
                  mr.res0 > 0 ? mr.res / mr.res0 : 0.0, s->rtol);
    else {
        st->status = SOLVE_CONVERGED;
        st->reason[0] = '\0';
    }
    solve_hessian_stats(H, st);
    return MPM_OK;
}

static void si_view(const OuterMethod *self, FILE *f)
{
    const SemiImplicit *s = (const SemiImplicit *)self;
    fprintf(f,
            "  semi-implicit (Stomakhin et al. 2013): one MINRES solve (relative tolerance %g) of the unprojected %s "
            "Hessian at %s per step, no line search\n",
            s->rtol, self->assembled ? "assembled" : "matrix-free", s->at_guess ? "the given dv" : "x^n (dv = -v^n)");
}

static void si_destroy(OuterMethod *self)
{
    SemiImplicit *s = (SemiImplicit *)self;
    free(s->g);
    free(s->rhs);
    free(s->p);
    free(s->tmp);
    free(s->diag);
    bsr_free(&s->H);
    minres_work_free(&s->mw);
    free(s);
}

const OuterMethodOps outer_semi_implicit = {
    "semi-implicit",
    "Stomakhin et al. 2013: one linearised backward-Euler step (MINRES on the unprojected Hessian at x^n), no line "
    "search",
    0u, si_create, si_solve, si_view, si_destroy};
