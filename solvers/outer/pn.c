/* Projected Newton (SPEC 5; HOT §5, reference §4): at every iterate the
 * projected (SPD) Hessian is rebuilt, H p = -g is solved inexactly by PCG
 * preconditioned by the inverse approximation, with the forcing term
 * eta = min(0.5, sqrt(max(rho0, tau))), and the line-search strategy takes
 * the step.
 *
 * Options: matrix_free (0): 1 applies H through the matrix-free product
 * (SPEC 3) and sets the inverse approximation up from the diagonal blocks
 * only (HOT PN-PCG(MF)); forcing (cn): the PCG stop, "cn" the forcing term
 * above on the preconditioned norm with tau the CN floor of SPEC 4, "gast"
 * what the HOT code runs as Gast15 (USE_GAST15_METRIC, reference §3 item 7):
 * sqrt(r^T M^-1 r) < eta rho0 with eta = min(0.5, sqrt(max(||g||, tau_g))),
 * ||g|| the plain L2 norm of the gradient and tau_g the termination
 * tolerance on it (the `tau` of stop=l2). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/outer_method.h"
#include "solvers/krylov/pcg.h"

typedef struct {
    OuterMethod base;
    int cap;
    int forcing_gast;
    double *g, *g_new, *p, *rhs, *dv_new, *diag; /* 3n each, diag 9n */
    Bsr H;
    PcgWork pcg;
} Pn;

extern const OuterMethodOps outer_pn;

static int pn_create(SolverOptions *opt, OuterMethod **out)
{
    int st = MPM_OK;
    int matrix_free = solver_opt_int(opt, "matrix_free", 0, 0, 1, &st);
    if (st) return st;
    const char *forcing = solver_opt_string(opt, "forcing", "cn");
    if (strcmp(forcing, "cn") != 0 && strcmp(forcing, "gast") != 0)
        return mpm_error(MPM_EINPUT, "solver option forcing=%s: expected cn or gast", forcing);
    Pn *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: projected Newton");
    s->base.ops = &outer_pn;
    s->base.assembled = !matrix_free;
    s->forcing_gast = strcmp(forcing, "gast") == 0;
    *out = &s->base;
    return MPM_OK;
}

static int pn_solve(OuterMethod *self, SolveCtx *c, double *dv, SolveStats *st)
{
    Pn *s = (Pn *)self;
    StepProblem *pb = c->pb;
    const size_t len = 3 * (size_t)pb->n_nodes;
    double **vecs[] = {&s->g, &s->g_new, &s->p, &s->rhs, &s->dv_new, &s->diag};
    const size_t per[] = {3, 3, 3, 3, 3, 9};
    int status = solve_reserve(vecs, per, 6, pb->n_nodes, &s->cap);
    if (status) return status;
    Bsr *H = self->assembled ? &s->H : NULL;

    double E = solve_evaluate(c, dv, s->g, st);
    const double tau = problem_tau(pb, c->set->eps);
    const double tau_g = solve_gradient_tolerance(c);
    LinearOp op;
    Projection proj;
    solve_hessian_op(c, H, &op);
    solve_projection(c, &proj);
    for (int it = 0;; ++it) {
        if (solve_should_stop(c, s->g, E, it, st)) break;
        st->outer_iters++;
        if ((status = solve_assemble(c, H, s->diag, st))) return status;
        if ((status = solve_setup_inverse(c, H, s->diag, &op, &proj, st))) return status;

        for (size_t k = 0; k < len; ++k) s->rhs[k] = -s->g[k];
        PcgOptions po = {.stop = PCG_FORCING, .tau = tau, .max_iters = c->set->max_linear,
                         .deadline = c->set->deadline};
        if (s->forcing_gast) {
            po.stop = PCG_RELATIVE;
            po.rel_tol = fmin(0.5, sqrt(fmax(vec_norm(len, s->g), tau_g)));
        }
        PcgResult pr;
        status = solve_pcg(c, &op, &proj, s->rhs, s->p, &po, &s->pcg, &pr, st);
        if (status) return status;
        if (pr.timed_out) {
            solve_end(st, SOLVE_TIMEOUT, "time limit %s reached in PCG at outer iteration %d",
                      deadline_reason(&c->set->deadline), it);
            break;
        }

        double gTp = vec_dot(len, s->g, s->p);
        /* PCG from p = 0 keeps g^T p = -p^T H p, so -g^T p / 2 is the model
         * decrease of the inexact Newton step, short of the exact one's by
         * r^T H^-1 r / 2 for the PCG residual r: estimated by the
         * preconditioned rho^2 / 2 (exact when M = H; SPEC 4.1). None
         * without a PCG iteration (a cap of 0). */
        double gTp_newton = pr.iters == 0 && pr.rho0 > 0.0 ? NAN : gTp - pr.rho * pr.rho;
        if (solve_direction_converged(c, gTp_newton, E, st)) break;
        if (!(gTp < 0.0)) {
            /* not a descent direction (round-off or a capped solve): fall back
             * to steepest descent rather than stall */
            vec_copy(len, s->g, s->p);
            vec_scale(len, -1.0, s->p);
            gTp = -vec_dot(len, s->g, s->g);
        }
        int stalled;
        if ((status = solve_take_step(c, dv, &s->g, &s->g_new, s->p, &E, gTp, s->dv_new, st, &stalled))) return status;
        if (stalled) break;
    }
    solve_hessian_stats(H, st);
    return MPM_OK;
}

static void pn_view(const OuterMethod *self, FILE *f)
{
    const Pn *s = (const Pn *)self;
    fprintf(f, "  projected Newton: %s Hessian, inexact PCG with the forcing term %s\n",
            self->assembled ? "assembled" : "matrix-free",
            s->forcing_gast ? "min(0.5, sqrt(max(||g||, tau_g))) (HOT's Gast15)" : "min(0.5, sqrt(max(rho0, tau)))");
}

static void pn_destroy(OuterMethod *self)
{
    Pn *s = (Pn *)self;
    free(s->g);
    free(s->g_new);
    free(s->p);
    free(s->rhs);
    free(s->dv_new);
    free(s->diag);
    bsr_free(&s->H);
    pcg_work_free(&s->pcg);
    free(s);
}

const OuterMethodOps outer_pn = {
    "pn",      "projected Newton: projected Hessian every iteration, inexact PCG, line search (SPEC 5)",
    OUTER_DESCENT | OUTER_TO_TOLERANCE, pn_create, pn_solve, pn_view, pn_destroy};
