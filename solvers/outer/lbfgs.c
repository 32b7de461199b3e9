/* L-BFGS with a problem-specific initial inverse Hessian (SPEC 7; HOT §4,
 * Algorithm 3; reference §6). At iteration 0 of every step the BC-projected
 * Hessian is built at dv^0 and the inverse approximation (a multigrid
 * V-cycle for HOT, an inexact PCG for LBFGS-H, ...) is set up on it; the
 * two-loop recursion applies it to q with no gamma scaling, the result is
 * projected, the line-search strategy takes the step, and the pair
 * (s, y = g_new - g_old) is kept only if y^T s > 0.
 *
 * Options: window (8): pairs kept, 1..64. */
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/outer_method.h"

typedef struct {
    OuterMethod base;
    int window;
    int cap;
    double *g, *g_new, *q, *d, *dv_new, *diag; /* 3n each, diag 9n */
    double *S, *Y;                            /* window x 3n (a ring buffer) */
    double *rho, *xi;                         /* window */
    Bsr H;
} Lbfgs;

extern const OuterMethodOps outer_lbfgs;

static int lbfgs_create(SolverOptions *opt, OuterMethod **out)
{
    int st = MPM_OK;
    int window = solver_opt_int(opt, "window", 8, 1, 64, &st);
    if (st) return st;
    Lbfgs *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: L-BFGS");
    s->base.ops = &outer_lbfgs;
    s->base.assembled = 1;
    s->window = window;
    s->rho = calloc((size_t)window, sizeof(double));
    s->xi = calloc((size_t)window, sizeof(double));
    if (!s->rho || !s->xi) {
        free(s->rho);
        free(s->xi);
        free(s);
        return mpm_error(MPM_EINTERNAL, "out of memory: L-BFGS");
    }
    *out = &s->base;
    return MPM_OK;
}

static int lbfgs_solve(OuterMethod *self, SolveCtx *c, double *dv, SolveStats *st)
{
    Lbfgs *s = (Lbfgs *)self;
    StepProblem *pb = c->pb;
    const size_t len = 3 * (size_t)pb->n_nodes;
    const size_t m = (size_t)s->window;
    double **vecs[] = {&s->g, &s->g_new, &s->q, &s->d, &s->dv_new, &s->diag, &s->S, &s->Y};
    const size_t per[] = {3, 3, 3, 3, 3, 9, 3 * m, 3 * m};
    int status = solve_reserve(vecs, per, 8, pb->n_nodes, &s->cap);
    if (status) return status;

    double E = solve_evaluate(c, dv, s->g, st);
    LinearOp op;
    Projection proj;
    solve_hessian_op(c, &s->H, &op);
    solve_projection(c, &proj);
    int count = 0, head = 0; /* ring buffer of the newest `count` pairs; head = next slot */
    for (int it = 0;; ++it) {
        if (solve_should_stop(c, s->g, E, it, st)) break;
        st->outer_iters++;
        if (it == 0) {
            /* the Hessian and its inverse approximation, once per step, lagged at dv^0 */
            if ((status = solve_assemble(c, &s->H, s->diag, st))) return status;
            if ((status = solve_setup_inverse(c, &s->H, s->diag, &op, &proj, st))) return status;
            count = head = 0;
        }
        /* two-loop recursion on q = -g */
        double *q = s->q, *d = s->d;
        for (size_t k = 0; k < len; ++k) q[k] = -s->g[k];
        for (int k = 0; k < count; ++k) {
            int i = (head - 1 - k + s->window) % s->window;
            double *Si = s->S + len * (size_t)i, *Yi = s->Y + len * (size_t)i;
            s->xi[i] = s->rho[i] * vec_dot(len, Si, q);
            vec_axpy(len, -s->xi[i], Yi, q);
        }
        status = inv_apply(c->inv, q, d);
        if (status) return status;
        problem_project(pb, d);
        for (int k = count - 1; k >= 0; --k) {
            int i = (head - 1 - k + s->window) % s->window;
            double *Si = s->S + len * (size_t)i, *Yi = s->Y + len * (size_t)i;
            double beta = s->rho[i] * vec_dot(len, Yi, d);
            vec_axpy(len, s->xi[i] - beta, Si, d);
        }
        double gTd = vec_dot(len, s->g, d);
        /* the quasi-Newton model's decrease (SPEC 4.1) */
        if (solve_direction_converged(c, gTd, E, st)) break;
        if (!(gTd < 0.0)) {
            vec_copy(len, s->g, d);
            vec_scale(len, -1.0, d);
            gTd = -vec_dot(len, s->g, s->g);
        }
        LineSearchOutcome lr;
        if ((status = solve_line_search(c, dv, s->g, d, E, gTd, s->dv_new, s->g_new, &lr, st))) return status;
        if (lr.stalled) break;
        /* new pair s = dv_new - dv, y = g_new - g (stored in the head slot) */
        double *Sn = s->S + len * (size_t)head, *Yn = s->Y + len * (size_t)head;
        for (size_t k = 0; k < len; ++k) {
            Sn[k] = s->dv_new[k] - dv[k];
            Yn[k] = s->g_new[k] - s->g[k];
        }
        double ys = vec_dot(len, Yn, Sn);
        if (ys > 0.0 && isfinite(ys)) {
            s->rho[head] = 1.0 / ys;
            head = (head + 1) % s->window;
            if (count < s->window) ++count;
        }
        vec_copy(len, s->dv_new, dv);
        double *t = s->g;
        s->g = s->g_new;
        s->g_new = t;
        E = lr.energy;
    }
    st->hessian_blocks = s->H.nnzb;
    st->hessian_bytes = bsr_bytes(&s->H);
    return MPM_OK;
}

static void lbfgs_view(const OuterMethod *self, FILE *f)
{
    const Lbfgs *s = (const Lbfgs *)self;
    fprintf(f, "  L-BFGS: window %d, initial inverse = the inverse approximation set up once per step at dv^0\n",
            s->window);
}

static void lbfgs_destroy(OuterMethod *self)
{
    Lbfgs *s = (Lbfgs *)self;
    free(s->g);
    free(s->g_new);
    free(s->q);
    free(s->d);
    free(s->dv_new);
    free(s->diag);
    free(s->S);
    free(s->Y);
    free(s->rho);
    free(s->xi);
    bsr_free(&s->H);
    free(s);
}

const OuterMethodOps outer_lbfgs = {
    "lbfgs", "L-BFGS with the inverse approximation as initial inverse Hessian, set up once per step (SPEC 7)",
    OUTER_DESCENT | OUTER_TO_TOLERANCE, lbfgs_create, lbfgs_solve, lbfgs_view, lbfgs_destroy};
