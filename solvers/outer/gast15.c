/* The optimization integrator of Gast et al. 2015 (§3.1, applied to MPM in
 * §6.2; SPEC 8), outer method "gast15". Each iteration, at the iterate dv
 * with gradient g:
 *   - terminate when the stopping rule holds (the preset: ||g|| < tau, §3.1
 *     step 3; stop=cn compares it with the other solvers at equal accuracy);
 *   - Newton step on the true, UNPROJECTED Hessian (the tangent dP/dF is not
 *     made definite): CG from zero (solvers/krylov/pcg.c, preconditioned by the
 *     inverse approximation, for the preset Gast's rest-configuration
 *     diagonal of §6.2) to the relative tolerance
 *         ||H p + g|| < min(1/2, sigma sqrt(max(||g||, tau))) ||g||,
 *     sigma = 1 (§3.1 "Linear solver considerations"); when CG meets
 *     p^T H p <= 0 it returns its last iterate, or the right-hand side -g if
 *     that happens in its first iteration (§3.1 "Conjugate gradient");
 *   - downhill check (§3.1 "Downhill direction", kappa = 1e-2; in which norms:
 *     option downhill below): keep p if
 *     p.g < -kappa ||p|| ||g||, else -p if that passes, else -g;
 *   - length clamp (§3.1 step 6): ||p|| <= l with l = 1e3. Section 3 states
 *     it for position unknowns (metres); §6.2 solves the same minimisation
 *     for grid velocities, so here l is in m/s on the Euclidean norm of the
 *     whole 3n-vector of velocity increments;
 *   - the line-search strategy (the preset: strong Wolfe, alpha may exceed 1;
 *     solvers/line_search.c) and the step.
 * Initial guess (§3.1 "Initial guess"), in the velocity unknowns of §6.2:
 * x^(0) = x^n + dt v^n is v^(0) = v^n, i.e. dv = 0; the explicit guess
 * x^(0) = x^n + dt v^n + dt^2 M^-1 f(x^n) is dv = dt M^-1 f(x^n), f(x^n) the
 * elastic and gravity force at the grid's rest positions (F_p = F_p^n),
 * which is g's negative at dv = -v^n: dv = -v^n - M^-1 g(-v^n). Both keep the
 * Dirichlet components of the dv they are given; the one with the smaller
 * energy starts the solve (option initial_guess=given starts from the dv
 * handed in instead, e.g. dt g of HOT's reference).
 *
 * Options: matrix_free (1: Gast "never explicitly form[s] the matrix"),
 * sigma (1), kappa (1e-2), max_step (l, 1e3), initial_guess (gast|given),
 * downhill (mass|l2): the norms of the downhill check. "l2" is the check as
 * the paper prints it, in the Euclidean norm of the unknowns. On MPM grids,
 * whose nodal masses span orders of magnitude (nodes at the edge of the
 * material carry little mass), a good Newton step is routinely more than
 * 89.4 degrees from -g in that norm (cos < kappa = 1e-2) and the check
 * replaces it by -g: on twist's first step at scale 5.2 (stop=cn, eps
 * 1e-9) all of 1,472 directions (gradient descent, not converged after 60 s
 * where PN takes 4 s), on drop's first 8 frames 2,339 of 2,366 (37 s/frame
 * against 0.14 s). Gast et al.'s MPM timings (Fig. 18) cannot come from such a
 * method, so the default "mass" applies the same rule in the kinetic-energy
 * metric of the velocity unknowns, ||p||_M ||g||_{M^-1} with the lumped
 * grid mass M, falling back to -M^-1 g (the paper's check in mass-scaled
 * variables sqrt(m) dv): there 28 of 35 directions are Newton's on twist
 * (3 s), all 36 on drop.
 * The view reports how often CG stopped at indefiniteness, the downhill
 * check flipped p or fell back to -g, and the clamp acted. */
#include "solvers/outer/gast15.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/vec.h"
#include "solvers/outer_method.h"
#include "solvers/krylov/pcg.h"

int gast_downhill_direction(int n_nodes, const double *m, const double *g, double *p, double kappa, double *work)
{
    const size_t len = 3 * (size_t)n_nodes;
    double pg = vec_dot(len, p, g), pp, gg;
    if (m) {
        for (int i = 0; i < n_nodes; ++i)
            for (int d = 0; d < 3; ++d) work[3 * i + d] = m[i] * p[3 * i + d];
        pp = vec_dot(len, p, work);
        for (int i = 0; i < n_nodes; ++i)
            for (int d = 0; d < 3; ++d) work[3 * i + d] = g[3 * i + d] / m[i];
        gg = vec_dot(len, g, work);
    } else {
        pp = vec_dot(len, p, p);
        gg = vec_dot(len, g, g);
    }
    double bound = kappa * sqrt(pp) * sqrt(gg);
    if (pg < -bound) return GAST_DIR_NEWTON;
    if (-pg < -bound) { /* -p . g < -kappa ||p|| ||g|| */
        vec_scale(len, -1.0, p);
        return GAST_DIR_FLIPPED;
    }
    vec_copy(len, m ? work : g, p); /* work = M^-1 g */
    vec_scale(len, -1.0, p);
    return GAST_DIR_GRADIENT;
}

int gast_clamp_step(size_t len, double *p, double l)
{
    double norm = vec_norm(len, p);
    if (!(norm > l)) return 0;
    vec_scale(len, l / norm, p);
    return 1;
}

typedef struct {
    OuterMethod base;
    double sigma, kappa, max_step;
    int given_guess, mass_metric;
    long indefinite, flipped, gradient, clamped, newton; /* over the solver's life */
    int cap;
    double *g, *g_new, *p, *rhs, *dv_new, *diag, *cand; /* 3n each, diag 9n */
    Bsr H;
    PcgWork pcg;
} Gast15;

extern const OuterMethodOps outer_gast15;

static int gast15_create(SolverOptions *opt, OuterMethod **out)
{
    int st = MPM_OK;
    int matrix_free = solver_opt_int(opt, "matrix_free", 1, 0, 1, &st);
    double sigma = solver_opt_number(opt, "sigma", 1.0, &st);
    double kappa = solver_opt_number(opt, "kappa", 1e-2, &st);
    double max_step = solver_opt_number(opt, "max_step", 1e3, &st);
    const char *guess = solver_opt_string(opt, "initial_guess", "gast");
    const char *downhill = solver_opt_string(opt, "downhill", "mass");
    if (st) return st;
    if (strcmp(downhill, "l2") != 0 && strcmp(downhill, "mass") != 0)
        return mpm_error(MPM_EINPUT, "solver option downhill=%s: expected mass or l2", downhill);
    if (!(sigma > 0.0)) return mpm_error(MPM_EINPUT, "solver option sigma=%g: expected a positive number", sigma);
    if (!(kappa >= 0.0 && kappa < 1.0)) return mpm_error(MPM_EINPUT, "solver option kappa=%g: expected 0 <= kappa < 1", kappa);
    if (!(max_step > 0.0))
        return mpm_error(MPM_EINPUT, "solver option max_step=%g: expected a positive number (m/s)", max_step);
    if (strcmp(guess, "gast") != 0 && strcmp(guess, "given") != 0)
        return mpm_error(MPM_EINPUT, "solver option initial_guess=%s: expected gast or given", guess);
    Gast15 *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: gast15");
    s->base.ops = &outer_gast15;
    s->base.assembled = !matrix_free;
    s->sigma = sigma;
    s->kappa = kappa;
    s->max_step = max_step;
    s->given_guess = strcmp(guess, "given") == 0;
    s->mass_metric = strcmp(downhill, "mass") == 0;
    *out = &s->base;
    return MPM_OK;
}

/* §3.1 "Initial guess": the smaller-energy of dv = 0 and the explicit step,
 * both with dv's Dirichlet components. Leaves the cache at the choice and
 * returns its energy. */
static double initial_guess(Gast15 *s, SolveCtx *c, double *dv, SolveStats *st)
{
    StepProblem *pb = c->pb;
    const size_t len = 3 * (size_t)pb->n_nodes;
    const double *vn = pb->grid->v, *m = pb->grid->mass;
    double *rest = s->cand, *tmp = s->dv_new, *g = s->g;
    /* the force at the rest positions of the grid: F_p = F_p^n at dv = -v^n */
    for (size_t k = 0; k < len; ++k) rest[k] = -vn[k];
    solve_evaluate(c, rest, g, st);
    /* explicit: dv = -v^n - M^-1 g(-v^n) on the free part */
    for (int i = 0; i < pb->n_nodes; ++i)
        for (int d = 0; d < 3; ++d) rest[3 * i + d] = -vn[3 * i + d] - g[3 * i + d] / m[i];
    double *explicit_dv = s->p; /* scratch until the first direction */
    solve_keep_dirichlet(pb, dv, rest, explicit_dv, tmp);
    vec_zero(len, rest);
    solve_keep_dirichlet(pb, dv, rest, rest, tmp); /* dv = 0 on the free part */
    double E_explicit = solve_energy(c, explicit_dv, st);
    double E_zero = solve_energy(c, rest, st); /* the cache is at dv = 0 now */
    if (E_explicit < E_zero) {
        vec_copy(len, explicit_dv, dv);
        return solve_energy(c, dv, st);
    }
    vec_copy(len, rest, dv);
    return E_zero;
}

static int gast15_solve(OuterMethod *self, SolveCtx *c, double *dv, SolveStats *st)
{
    Gast15 *s = (Gast15 *)self;
    StepProblem *pb = c->pb;
    const size_t len = 3 * (size_t)pb->n_nodes;
    double **vecs[] = {&s->g, &s->g_new, &s->p, &s->rhs, &s->dv_new, &s->diag, &s->cand};
    const size_t per[] = {3, 3, 3, 3, 3, 9, 3};
    int status = solve_reserve(vecs, per, 7, pb->n_nodes, &s->cap);
    if (status) return status;
    Bsr *H = self->assembled ? &s->H : NULL;

    double E = s->given_guess ? solve_energy(c, dv, st) : initial_guess(s, c, dv, st);
    solve_gradient(c, dv, s->g, st);
    const double tau = solve_gradient_tolerance(c);
    LinearOp op;
    Projection proj;
    solve_hessian_op(c, H, &op);
    solve_projection(c, &proj);
    for (int it = 0;; ++it) {
        if (solve_should_stop(c, s->g, E, it, st)) break;
        st->outer_iters++;
        if ((status = solve_assemble_unprojected(c, H, s->diag, st))) return status;
        if ((status = solve_setup_inverse(c, H, s->diag, &op, &proj, st))) return status;

        const double gnorm = vec_norm(len, s->g);
        for (size_t k = 0; k < len; ++k) s->rhs[k] = -s->g[k];
        PcgOptions po = {.stop = PCG_RELATIVE_L2,
                         .rel_tol = fmin(0.5, s->sigma * sqrt(fmax(gnorm, tau))),
                         .max_iters = c->set->max_linear,
                         .deadline = c->set->deadline};
        PcgResult pr;
        status = solve_pcg(c, &op, &proj, s->rhs, s->p, &po, &s->pcg, &pr, st);
        if (!status && pr.timed_out) {
            solve_end(st, SOLVE_TIMEOUT, "time limit %s reached in CG at outer iteration %d",
                      deadline_reason(&c->set->deadline), it);
            break;
        }
        if (status) return status;
        s->indefinite += pr.indefinite;
        /* the CG iterate's model decrease, before the downhill check and the
         * clamp change p, with PN's residual correction while the curvature
         * was positive; none without a CG iteration (negative curvature at
         * once returns -g) (SPEC 4.1) */
        double gTcg = pr.iters == 0 && pr.rho0 > 0.0
                          ? NAN
                          : vec_dot(len, s->g, s->p) - (pr.indefinite ? 0.0 : pr.rho * pr.rho);
        if (solve_direction_converged(c, gTcg, E, st)) break;
        int dir = gast_downhill_direction(pb->n_nodes, s->mass_metric ? pb->grid->mass : NULL, s->g, s->p, s->kappa,
                                          s->rhs);
        s->newton += dir == GAST_DIR_NEWTON;
        s->flipped += dir == GAST_DIR_FLIPPED;
        s->gradient += dir == GAST_DIR_GRADIENT;
        s->clamped += gast_clamp_step(len, s->p, s->max_step);
        double gTp = vec_dot(len, s->g, s->p);

        int stalled;
        if ((status = solve_take_step(c, dv, &s->g, &s->g_new, s->p, &E, gTp, s->dv_new, st, &stalled))) return status;
        if (stalled) break;
    }
    solve_hessian_stats(H, st);
    return MPM_OK;
}

static void gast15_view(const OuterMethod *self, FILE *f)
{
    const Gast15 *s = (const Gast15 *)self;
    fprintf(f,
            "  Gast et al. 2015: Newton on the unprojected %s Hessian, CG to min(1/2, %g sqrt(max(||g||, tau))) "
            "stopping at indefiniteness, downhill check kappa %g (%s norms), clamp %g m/s, initial guess %s\n",
            self->assembled ? "assembled" : "matrix-free", s->sigma, s->kappa,
            s->mass_metric ? "kinetic-energy" : "Euclidean", s->max_step,
            s->given_guess ? "as given" : "the smaller-energy of dv = 0 and the explicit step");
    fprintf(f, "  directions: %ld Newton, %ld flipped (-p), %ld gradient (-g); CG stopped at indefiniteness %ld times; "
               "clamped %ld times\n", s->newton, s->flipped, s->gradient, s->indefinite, s->clamped);
}

static void gast15_destroy(OuterMethod *self)
{
    Gast15 *s = (Gast15 *)self;
    free(s->g);
    free(s->g_new);
    free(s->p);
    free(s->rhs);
    free(s->dv_new);
    free(s->diag);
    free(s->cand);
    bsr_free(&s->H);
    pcg_work_free(&s->pcg);
    free(s);
}

const OuterMethodOps outer_gast15 = {
    "gast15",
    "Gast et al. 2015: Newton on the unprojected Hessian, CG stopping at indefiniteness, downhill check, clamp (SPEC 8)",
    OUTER_DESCENT | OUTER_TO_TOLERANCE, gast15_create, gast15_solve, gast15_view, gast15_destroy};
