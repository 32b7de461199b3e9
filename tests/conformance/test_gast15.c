/* floor: driver */
/* needs: MPM_WITH_CHOLMOD */
/* The Gast et al. 2015 parts (SPEC 8): solvers/outer/gast15.c, the strong Wolfe
 * line search, solvers/inverse/gast_diagonal.c and solvers/outer/semi_implicit.c.
 *
 *  1. gast-diagonal is the rest-configuration stiffness diagonal: at
 *     F = F^n = I it equals the diagonal of the assembled (unprojected)
 *     Hessian entry by entry (Gast §6.2).
 *  2. The downhill check (Gast §3.1, kappa = 1e-2) on an indefinite Hessian
 *     made for it: the exact Newton step points uphill and is flipped, a
 *     step orthogonal to g is replaced by -g, an SPD one is kept; CG on the
 *     same indefinite system stops at the negative curvature with a downhill
 *     iterate, so the check never flips a CG step; the kinetic-energy
 *     variant keeps a mass-scaled Newton step the Euclidean check rejects.
 *     The clamp scales a long step to length l exactly.
 *  3. Strong Wolfe: on a step problem, a direction 1e4 times too short is
 *     accepted at alpha > 1, one 1e4 times too long at alpha < 1 after zoom,
 *     both satisfying both conditions (re-evaluated here).
 *  4. gast15 on the first step of stretched-box and bar3 (coarse scales)
 *     with a line search that checks the strong Wolfe conditions at every
 *     accepted step and the clamp on every direction: reaches ||g|| < tau
 *     (recomputed), starts from the smaller-energy of Gast's two initial
 *     guesses, and agrees with pn-cholmod (eps 1e-12) within the bound its
 *     tolerance implies. With e = dv - dv*, g(dv) = Hbar e (Hbar the Hessian
 *     averaged over the segment, H at dv*), so |e|_H = |g|_{H^-1} to first
 *     order; H = M + dt^2 K >= M where K >= 0, hence
 *         |e|_H <= |g|_{M^-1} <= ||g|| / sqrt(min_i m_i) < tau / sqrt(min m).
 *     Checked: |e|_H <= 2 |g|_{M^-1} + r* (factor 2: the curvature along the
 *     segment within a factor 2 of H's, as in test_solvers.c; r* the
 *     reference's own |g*|_{H^-1}), |e|_H >= |g|_{H^-1} / 2 - r* (the dv
 *     returned is the one judged), and K >= 0 along e (|g|_{H^-1} <= |g|_{M^-1}).
 *  The first CG of gast15 (||r|| relative, unprojected Hessian, tau = the
 *  L2 tolerance or, with stop=cn, problem_tau) and of gast15-hot (the HOT
 *  code's preconditioned-norm rule) takes exactly the iterations of
 *  pcg_solve run here with the rule stated.
 *  5. semi-implicit on a linear problem (small deformation): equals one
 *     exact Newton step (CHOLMOD on the unprojected Hessian) from x^n, to
 *     1e-8 of the step, and is within 1e-3 of the step from the converged
 *     nonlinear solution; linearize=guess equals the Newton step from the
 *     given dv; its residual is the CN residual of the returned dv. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/step.h"
#include "core/vec.h"
#include "experiments/driver/registry.h"
#include "solvers/outer/gast15.h"
#include "solvers/krylov/pcg.h"
#include "tests/common/fixture.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

static void spmv_op(const void *ctx, const double *x, double *y) { bsr_spmv((const Bsr *)ctx, x, y); }
static void project_op(const void *ctx, double *v) { problem_project((const StepProblem *)ctx, v); }

/* CHOLMOD set up on the true (unprojected, BC-projected) Hessian at the
 * problem's cached iterate: H assembled into *H, diagonal scratch D (9n) */
static int factor_true_hessian(StepProblem *pb, Bsr *H, double *D, InvApprox *chol)
{
    int st = problem_tangent(pb, 0);
    if (!st) st = problem_assemble(pb, H);
    if (st) return st;
    bsr_diagonal(H, D);
    LinearOp op = {pb->n_nodes, spmv_op, H};
    Projection proj = {project_op, pb};
    InvSetupInput in = {.n_nodes = pb->n_nodes, .H = H, .diag = D, .op = &op, .proj = &proj};
    return inv_setup(chol, &in);
}

/* ---- 1. gast-diagonal ---- */

static void rest_diagonal(void)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 8;
    o.F_noise = 0.0; /* F^n = I */
    o.two_materials = 1;
    o.dt = 0.02;
    Fixture f;
    int st = fixture_build(&f, &o);
    CHECK(st == MPM_OK, "fixture: %s", mpm_last_error());
    if (st) return;
    StepProblem *pb = &f.pb;
    const int n = pb->n_nodes;
    const size_t len = 3 * (size_t)n;
    double *dv = malloc(sizeof(double) * len), *one = malloc(sizeof(double) * len), *z = malloc(sizeof(double) * len),
           *D = malloc(sizeof(double) * 9 * (size_t)n);
    for (size_t k = 0; k < len; ++k) dv[k] = -f.g.v[k], one[k] = 1.0; /* F = F^n = I */
    problem_energy(pb, dv);
    Bsr H = {0};
    st = problem_tangent(pb, 0);
    if (!st) st = problem_assemble(pb, &H);
    InvApprox *L = NULL;
    if (!st) st = inv_create(registry_find_inverse("gast-diagonal"), NULL, &L);
    InvSetupInput in = {.n_nodes = n, .problem = pb};
    if (!st) st = inv_setup(L, &in);
    if (!st) st = inv_apply(L, one, z);
    CHECK(st == MPM_OK, "gast-diagonal: %s", mpm_last_error());
    if (!st) {
        bsr_diagonal(&H, D);
        double worst = 0.0;
        for (int i = 0; i < n; ++i)
            for (int a = 0; a < 3; ++a) worst = fmax(worst, rel_diff(1.0 / z[3 * i + a], D[9 * i + 4 * a], 0.0));
        CHECK(worst < 1e-12, "L_ii vs the Hessian diagonal at the rest configuration: worst relative difference %.3e",
              worst);
        printf("gast-diagonal at F = F^n = I: %d nodes, worst relative difference to diag(H) %.2e\n", n, worst);
    }
    inv_destroy(L);
    bsr_free(&H);
    free(dv), free(one), free(z), free(D);
    fixture_free(&f);
}

/* ---- 2. downhill check and clamp ---- */

#define DN 2 /* nodes of the dense systems */
#define DL (3 * DN)
typedef struct {
    double a[DL * DL];
} Dense;

static void dense_apply(const void *ctx, const double *x, double *y)
{
    const Dense *A = ctx;
    for (int i = 0; i < DL; ++i) {
        y[i] = 0.0;
        for (int j = 0; j < DL; ++j) y[i] += A->a[i * DL + j] * x[j];
    }
}

static void downhill(void)
{
    double work[DL];
    /* H = diag(1, -1, 2, 3, 4, 5): indefinite; g = (1, 2, ...) gives the
     * exact Newton step p = -H^-1 g = (-1, 2, ...), uphill: p.g > 0 */
    const double h[DL] = {1, -1, 2, 3, 4, 5};
    double g[DL] = {1, 2, 0, 0, 0, 0}, p[DL];
    for (int i = 0; i < DL; ++i) p[i] = -g[i] / h[i];
    CHECK(vec_dot(DL, p, g) > 0, "the made-up Newton step is uphill");
    int d = gast_downhill_direction(DN, NULL, g, p, 1e-2, work);
    CHECK(d == GAST_DIR_FLIPPED && p[0] == 1 && p[1] == -2, "uphill Newton step: direction %d, p = (%g, %g)", d, p[0],
          p[1]);
    /* g = (1, 1): p = (-1, 1) is orthogonal to g, neither p nor -p passes */
    double g2[DL] = {1, 1, 0, 0, 0, 0};
    for (int i = 0; i < DL; ++i) p[i] = -g2[i] / h[i];
    d = gast_downhill_direction(DN, NULL, g2, p, 1e-2, work);
    CHECK(d == GAST_DIR_GRADIENT && p[0] == -1 && p[1] == -1, "orthogonal step: direction %d, p = (%g, %g)", d, p[0],
          p[1]);
    /* just inside / outside the cone: cos = 0.011 passes, 0.009 does not */
    for (int k = 0; k < 2; ++k) {
        double c = k ? 0.009 : 0.011;
        double gg[DL] = {1, 0, 0, 0, 0, 0}, pp[DL] = {-c, sqrt(1 - c * c), 0, 0, 0, 0};
        d = gast_downhill_direction(DN, NULL, gg, pp, 1e-2, work);
        CHECK(d == (k ? GAST_DIR_GRADIENT : GAST_DIR_NEWTON), "cos %.3f: direction %d", c, d);
    }
    /* SPD: the Newton step is kept as it is */
    const double hs[DL] = {1, 2, 3, 4, 5, 6};
    double q[DL];
    for (int i = 0; i < DL; ++i) p[i] = q[i] = -g[i] / hs[i];
    d = gast_downhill_direction(DN, NULL, g, p, 1e-2, work);
    CHECK(d == GAST_DIR_NEWTON && memcmp(p, q, sizeof p) == 0, "SPD Newton step kept: direction %d", d);

    /* CG on the indefinite system: stops at negative curvature with a
     * downhill iterate, which the check never flips */
    Dense A;
    memset(&A, 0, sizeof A);
    unsigned long long seed = 3;
    for (int i = 0; i < DL; ++i) A.a[i * DL + i] = h[i] * 10;
    for (int i = 0; i < DL; ++i)
        for (int j = i + 1; j < DL; ++j) A.a[i * DL + j] = A.a[j * DL + i] = test_uniform(&seed, -1, 1);
    LinearOp op = {DN, dense_apply, &A};
    PcgWork w = {0};
    int indefinite = 0, flipped = 0;
    for (int t = 0; t < 20; ++t) {
        double b[DL], x[DL];
        for (int i = 0; i < DL; ++i) g[i] = test_uniform(&seed, -1, 1), b[i] = -g[i];
        PcgOptions po = {.stop = PCG_RELATIVE_L2, .rel_tol = 1e-10, .max_iters = 100};
        PcgResult pr;
        pcg_solve(&op, NULL, NULL, b, x, &po, &w, &pr);
        indefinite += pr.indefinite;
        CHECK(vec_dot(DL, x, g) < 0, "CG's iterate is downhill (trial %d, indefinite %d)", t, pr.indefinite);
        flipped += gast_downhill_direction(DN, NULL, g, x, 1e-2, work) == GAST_DIR_FLIPPED;
    }
    CHECK(indefinite >= 10 && flipped == 0, "CG met indefiniteness in %d of 20 solves, the check flipped %d", indefinite,
          flipped);
    pcg_work_free(&w);

    /* kinetic-energy metric: with node masses (1e-6, 1) the mass-scaled
     * Newton step p = -M^-1 g is 89.9 degrees off -g in the Euclidean norm */
    const double m[DN] = {1e-6, 1};
    double gm[DL] = {1e-3, 0, 0, 1, 0, 0}, pm[DL];
    for (int i = 0; i < DL; ++i) pm[i] = -gm[i] / m[i / 3];
    memcpy(q, pm, sizeof q);
    d = gast_downhill_direction(DN, NULL, gm, q, 1e-2, work);
    CHECK(d == GAST_DIR_GRADIENT, "Euclidean check rejects the mass-scaled step: direction %d", d);
    memcpy(q, pm, sizeof q);
    d = gast_downhill_direction(DN, m, gm, q, 1e-2, work);
    CHECK(d == GAST_DIR_NEWTON && memcmp(q, pm, sizeof q) == 0, "mass-metric check keeps it: direction %d", d);
    double up[DL] = {0, 0, 0, 0, 1, 0}; /* orthogonal: fallback -M^-1 g */
    d = gast_downhill_direction(DN, m, gm, up, 1e-2, work);
    CHECK(d == GAST_DIR_GRADIENT && fabs(up[0] + 1e3) < 1e-9 && up[3] == -1, "mass-metric fallback -M^-1 g: (%g, %g)",
          up[0], up[3]);

    /* clamp */
    double c3[DL] = {3, 4, 0, 0, 0, 0};
    CHECK(gast_clamp_step(DL, c3, 10) == 0 && c3[0] == 3, "short step not clamped");
    CHECK(gast_clamp_step(DL, c3, 1) == 1 && fabs(vec_norm(DL, c3) - 1) < 1e-15 && fabs(c3[0] - 0.6) < 1e-15,
          "clamped to length 1: (%g, %g)", c3[0], c3[1]);
}

/* ---- 3, 4: line search checks ---- */

typedef struct {
    int steps, violations, above_one, fallback, long_dirs;
    double max_step;  /* clamp to check (0: none) */
    double max_alpha;
} WolfeLog;
static WolfeLog g_log;
static const LineSearchOps *g_wolfe;

/* verifies the strong Wolfe conditions at the point the strategy accepted */
static int checked_wolfe(StepProblem *pb, const double *dv, const double *p, double E0, const double *g0, double gTp,
                         const LineSearchParams *prm, double *dv_new, double *g_new, LineSearchOutcome *out)
{
    const size_t len = 3 * (size_t)pb->n_nodes;
    if (g_log.max_step > 0 && vec_norm(len, p) > g_log.max_step * (1 + 1e-12)) g_log.long_dirs++;
    int st = g_wolfe->search(pb, dv, p, E0, g0, gTp, prm, dv_new, g_new, out);
    if (st || out->stalled) return st;
    g_log.steps++;
    g_log.fallback += !out->conditions_met;
    double d = vec_dot(len, g_new, p);
    int ok = out->energy <= E0 + WOLFE_C1 * out->alpha * gTp && fabs(d) <= WOLFE_C2 * fabs(gTp) && out->have_gradient;
    /* the cache and g_new belong to dv_new */
    double *g2 = malloc(sizeof(double) * len);
    double E = problem_energy(pb, dv_new);
    problem_gradient(pb, dv_new, g2);
    for (size_t k = 0; k < len && ok; ++k) ok = g2[k] == g_new[k];
    ok = ok && E == out->energy;
    free(g2);
    g_log.violations += !ok;
    g_log.above_one += out->alpha > 1.0;
    g_log.max_alpha = fmax(g_log.max_alpha, out->alpha);
    return MPM_OK;
}

/* p = -P M^-1 g at dv0 times `scale`, alpha from the Wolfe search */
static void wolfe_alpha(StepProblem *pb, double scale, double *alpha_out, int *ok_out)
{
    const size_t len = 3 * (size_t)pb->n_nodes;
    double *dv = malloc(sizeof(double) * len), *g = malloc(sizeof(double) * len), *p = malloc(sizeof(double) * len),
           *dn = malloc(sizeof(double) * len), *gn = malloc(sizeof(double) * len);
    problem_initial_guess(pb, dv);
    double E0 = problem_energy(pb, dv);
    problem_gradient(pb, dv, g);
    for (int i = 0; i < pb->n_nodes; ++i)
        for (int d = 0; d < 3; ++d) p[3 * i + d] = -scale * g[3 * i + d] / pb->grid->mass[i];
    problem_project(pb, p);
    LineSearchParams prm = {60};
    LineSearchOutcome out;
    double gTp = vec_dot(len, g, p);
    int st = g_wolfe->search(pb, dv, p, E0, g, gTp, &prm, dn, gn, &out);
    double E = problem_energy(pb, dn);
    problem_gradient(pb, dn, g);
    double d = vec_dot(len, g, p);
    *alpha_out = out.alpha;
    *ok_out = st == MPM_OK && !out.stalled && out.conditions_met && E <= E0 + WOLFE_C1 * out.alpha * gTp &&
              fabs(d) <= WOLFE_C2 * fabs(gTp);
    free(dv), free(g), free(p), free(dn), free(gn);
}

static void wolfe_steps(void)
{
    SceneStep s;
    int st = scene_step_open(&s, "stretched-box", 3.6);
    CHECK(st == MPM_OK, "stretched-box: %s", mpm_last_error());
    if (!st) {
        /* the mass-scaled gradient step, the steepest descent direction of
         * the kinetic-energy metric: at scale 1 the line minimum is near
         * alpha ~ 2e-3 here, so 1e-7 of it is far too short and 30 of it far
         * too long */
        double a_short, a_long;
        int ok_short, ok_long;
        wolfe_alpha(&s.sim.pb, 1e-7, &a_short, &ok_short);
        wolfe_alpha(&s.sim.pb, 30.0, &a_long, &ok_long);
        CHECK(ok_short && a_short > 1.0, "short direction: alpha %g, strong Wolfe %d", a_short, ok_short);
        CHECK(ok_long && a_long < 1.0, "long direction: alpha %g, strong Wolfe %d", a_long, ok_long);
        printf("strong Wolfe: alpha %g on a short direction, %g on a long one\n", a_short, a_long);
    }
    scene_step_close(&s);
}

typedef struct {
    double E0;
} Trace0;

static void first_energy(void *ctx, int iter, double elapsed, double residual, double energy)
{
    (void)elapsed;
    (void)residual;
    if (iter == 0) ((Trace0 *)ctx)->E0 = energy;
}

/* one gast15 solve on the first step of a scene: checks 4 */
static void gast15_scene(const char *scene, double scale, double tau)
{
    char spec[96];
    snprintf(spec, sizeof spec, "gast15:tau=%g,max_step=%g", tau, 5.0);
    SceneStep s;
    int st = scene_step_open(&s, scene, scale);
    CHECK(st == MPM_OK, "%s: %s", scene, mpm_last_error());
    Solver *gs = NULL, *ref = NULL;
    if (!st) st = solver_from_spec(spec, NULL, 0, &gs);
    if (!st) st = solver_from_spec("pn-cholmod", NULL, 0, &ref);
    CHECK(st == MPM_OK, "%s: solvers: %s", scene, mpm_last_error());
    if (st) {
        solver_destroy(gs);
        scene_step_close(&s);
        return;
    }
    StepProblem *pb = &s.sim.pb;
    const int n = pb->n_nodes;
    const size_t len = 3 * (size_t)n;
    double *dv = malloc(sizeof(double) * len), *dvr = malloc(sizeof(double) * len), *g = malloc(sizeof(double) * len),
           *w = malloc(sizeof(double) * len), *y = malloc(sizeof(double) * len), *t = malloc(sizeof(double) * len),
           *D = malloc(sizeof(double) * 9 * (size_t)n);

    /* the smaller-energy of Gast's two initial guesses, computed here */
    problem_initial_guess(pb, dv);
    for (size_t k = 0; k < len; ++k) w[k] = -s.sim.grid.v[k];
    problem_energy(pb, w);
    problem_gradient(pb, w, g);
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) w[3 * i + d] = -s.sim.grid.v[3 * i + d] - g[3 * i + d] / s.sim.grid.mass[i];
    solve_keep_dirichlet(pb, dv, w, y, t);
    vec_zero(len, w);
    solve_keep_dirichlet(pb, dv, w, w, t);
    double E_guess = fmin(problem_energy(pb, y), problem_energy(pb, w));

    g_log = (WolfeLog){.max_step = 5.0};
    LineSearchOps checking = {"checked-wolfe", "", checked_wolfe};
    gs->ls = &checking;
    SolveSettings set;
    solve_settings_default(&set);
    SolveStats ss;
    Trace0 tr = {NAN};
    st = solver_solve(gs, pb, &set, dv, &ss, NULL, first_energy, &tr);
    CHECK(st == MPM_OK && ss.status == SOLVE_CONVERGED, "%s gast15: status %s (%s)", scene,
          solve_status_name(ss.status), ss.reason);
    CHECK(tr.E0 == E_guess, "%s: starts at E %.17g, the smaller initial guess has %.17g", scene, tr.E0, E_guess);
    problem_energy(pb, dv);
    problem_gradient(pb, dv, g);
    const double gnorm = vec_norm(len, g);
    CHECK(gnorm < tau, "%s: ||g|| %.3e at the returned dv, tau %g", scene, gnorm, tau);
    CHECK(g_log.steps == ss.outer_iters && g_log.violations == 0 && g_log.fallback == 0 && g_log.long_dirs == 0,
          "%s: %d line searches for %d iterations, %d violate strong Wolfe, %d took the budget fallback, %d "
          "directions longer than the clamp", scene, g_log.steps, ss.outer_iters, g_log.violations, g_log.fallback,
          g_log.long_dirs);
    printf("%s: gast15 %d iterations, %ld CG; ||g|| %.2e < %g; %d steps with alpha > 1 (largest %g)\n", scene,
           ss.outer_iters, ss.linear_iters, gnorm, tau, g_log.above_one, g_log.max_alpha);

    /* the reference */
    SolveSettings rs;
    solve_settings_default(&rs);
    rs.eps = 1e-12;
    problem_initial_guess(pb, dvr);
    SolveStats sr;
    st = solver_solve(ref, pb, &rs, dvr, &sr, NULL, NULL, NULL);
    CHECK(st == MPM_OK && sr.status == SOLVE_CONVERGED, "%s pn-cholmod: %s", scene, solve_status_name(sr.status));

    /* energy norm of the true Hessian at dv* (one CHOLMOD factorisation) */
    Bsr H = {0};
    InvApprox *chol = NULL;
    problem_energy(pb, dvr);
    if (!st) st = inv_create(registry_find_inverse("cholmod"), NULL, &chol);
    if (!st) st = factor_true_hessian(pb, &H, D, chol);
    CHECK(st == MPM_OK, "%s: CHOLMOD on the true Hessian at dv*: %s", scene, mpm_last_error());
    if (!st) {
        double rstar, r, gm, e;
        problem_gradient(pb, dvr, g); /* the cache is at dvr */
        inv_apply(chol, g, y);
        rstar = sqrt(fmax(vec_dot(len, g, y), 0.0));
        problem_energy(pb, dv);
        problem_gradient(pb, dv, g);
        inv_apply(chol, g, y);
        r = sqrt(fmax(vec_dot(len, g, y), 0.0));
        gm = 0.0;
        for (int i = 0; i < n; ++i)
            for (int d = 0; d < 3; ++d) gm += g[3 * i + d] * g[3 * i + d] / pb->grid->mass[i];
        gm = sqrt(gm);
        for (size_t k = 0; k < len; ++k) w[k] = dv[k] - dvr[k];
        bsr_spmv(&H, w, y);
        e = sqrt(fmax(vec_dot(len, w, y), 0.0));
        double mmin = INFINITY;
        for (int i = 0; i < n; ++i) mmin = fmin(mmin, pb->grid->mass[i]);
        CHECK(r <= gm * (1 + 1e-9), "%s: |g|_H^-1 %.4e > |g|_M^-1 %.4e (K not >= 0 along g)", scene, r, gm);
        CHECK(e <= 2.0 * gm + rstar && e >= 0.5 * r - rstar,
              "%s: |dv - dv*|_H %.4e outside [%.4e, %.4e] (|g|_H^-1 %.4e, |g|_M^-1 %.4e)", scene, e, 0.5 * r - rstar,
              2.0 * gm + rstar, r, gm);
        printf("  |dv - dv*|_H %.3e, |g|_H^-1 %.3e, bound 2 |g|_M^-1 + r* = %.3e, a priori tau / sqrt(min m) = %.3e\n",
               e, r, 2.0 * gm + rstar, tau / sqrt(mmin));
    }
    inv_destroy(chol);
    bsr_free(&H);
    solver_destroy(gs);
    solver_destroy(ref);
    free(dv), free(dvr), free(g), free(w), free(y), free(t), free(D);
    scene_step_close(&s);
}

/* ---- the CG tolerances of gast15 and gast15-hot ---- */

/* The first Newton iteration's CG (max_outer = 1) of `spec` needs exactly
 * as many iterations as pcg_solve run here with the rule the method states
 * (projected: gast15-hot; mode: PCG stop; rel: its relative tolerance). */
static void first_cg(const char *spec, int projected, PcgStop mode, int rel_from_cn)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 10;
    o.F_noise = 2e-5; /* small ||g||: the forcing term is below 1/2 and above its floor */
    o.v_noise = 1e-3;
    o.C_noise = 0.0;
    o.two_materials = 1;
    o.gravity[1] = -9.81;
    Fixture f;
    int st = fixture_build(&f, &o);
    CHECK(st == MPM_OK, "fixture: %s", mpm_last_error());
    if (st) return;
    StepProblem *pb = &f.pb;
    const int n = pb->n_nodes;
    const size_t len = 3 * (size_t)n;
    double *dv = malloc(sizeof(double) * len), *g = malloc(sizeof(double) * len), *x = malloc(sizeof(double) * len),
           *D = malloc(sizeof(double) * 9 * (size_t)n);
    Solver *s = NULL;
    st = solver_from_spec(spec, NULL, 0, &s);
    SolveSettings set;
    solve_settings_default(&set);
    set.max_outer = 1;
    SolveStats ss;
    problem_initial_guess(pb, dv);
    if (!st) st = solver_solve(s, pb, &set, dv, &ss, NULL, NULL, NULL);
    CHECK(st == MPM_OK && ss.outer_iters == 1, "%s: one iteration: %s", spec, mpm_last_error());
    /* the same linear solve by hand, at the starting point */
    problem_initial_guess(pb, dv);
    problem_energy(pb, dv);
    problem_gradient(pb, dv, g);
    double gn = vec_norm(len, g);
    double tau = rel_from_cn ? problem_tau(pb, set.eps) : 1e-3;
    double rel = fmin(0.5, sqrt(fmax(gn, tau)));
    vec_scale(len, -1.0, g);
    st = problem_tangent(pb, projected);
    problem_diagonal(pb, D);
    InvApprox *M = NULL;
    if (!st) st = inv_create(s->inv->ops, NULL, &M);
    LinearOp op = {n, (void (*)(const void *, const double *, double *))problem_hessvec, pb};
    Projection proj = {project_op, pb};
    InvSetupInput in = {.n_nodes = n, .diag = D, .op = &op, .proj = &proj, .problem = pb};
    if (!st) st = inv_setup(M, &in);
    PcgWork w = {0};
    PcgResult pr;
    PcgOptions po = {.stop = mode, .rel_tol = rel, .max_iters = set.max_linear};
    if (!st) st = pcg_solve(&op, M, &proj, g, x, &po, &w, &pr);
    CHECK(st == MPM_OK && pr.iters == ss.linear_iters && pr.iters >= 3,
          "%s: first CG took %ld iterations, the rule (relative %.4f) %d", spec, ss.linear_iters, rel, pr.iters);
    printf("%s: first CG %ld iterations = %d of pcg to relative %.4f (||g|| %.3e)\n", spec, ss.linear_iters,
           pr.iters, rel, gn);
    /* the floor tau_g itself: the L2 rule's tau, or the CN rule's L2 equivalent */
    SolveCtx c = {.pb = pb, .stop = s->stop, .stop_tol = isnan(s->stop_tol) ? set.eps : s->stop_tol};
    CHECK(solve_gradient_tolerance(&c) == tau, "%s: tau_g %.6e, expected %.6e", spec, solve_gradient_tolerance(&c), tau);
    pcg_work_free(&w);
    inv_destroy(M);
    solver_destroy(s);
    free(dv), free(g), free(x), free(D);
    fixture_free(&f);
}

/* ---- which tangent each method hands its inverse approximation ---- */

static int g_probe_projected = -1, g_probe_nodes;
static int probe_create(SolverOptions *opt, InvApprox **out);
static int probe_setup(InvApprox *self, const InvSetupInput *in)
{
    (void)self;
    g_probe_projected = in->problem->tangent_projected;
    return MPM_OK;
}
static int probe_apply(InvApprox *self, const double *r, double *z)
{
    (void)self;
    memcpy(z, r, sizeof(double) * 3 * (size_t)g_probe_nodes);
    return MPM_OK;
}
static void probe_view(const InvApprox *self, FILE *f, InvView *out)
{
    (void)self, (void)f, (void)out;
}
static void probe_destroy(InvApprox *self) { free(self); }
static const InvApproxOps g_probe_ops = {"probe", "records the tangent", probe_create, probe_setup, probe_apply,
                                         probe_view, probe_destroy, NULL, NULL, NULL};
static int probe_create(SolverOptions *opt, InvApprox **out)
{
    (void)opt;
    *out = calloc(1, sizeof(InvApprox));
    if (!*out) return MPM_EINTERNAL;
    (*out)->ops = &g_probe_ops;
    (*out)->caps = INV_MATRIX_FREE | INV_SYMMETRIC | INV_POSITIVE;
    return MPM_OK;
}

/* gast15 and semi-implicit run on the unprojected tangent, pn on the projected one */
static void tangents(void)
{
    const char *spec[3] = {"gast15", "semi-implicit", "pn-pcg-mf"};
    const int want[3] = {0, 0, 1};
    for (int k = 0; k < 3; ++k) {
        FixtureOptions o;
        fixture_default(&o);
        Fixture f;
        int st = fixture_build(&f, &o);
        g_probe_nodes = f.pb.n_nodes;
        double *dv = malloc(sizeof(double) * 3 * (size_t)f.pb.n_nodes);
        Solver *s = NULL;
        if (!st) st = solver_from_spec(spec[k], NULL, 0, &s);
        if (!st) {
            inv_destroy(s->inv);
            st = inv_create(&g_probe_ops, NULL, &s->inv);
        }
        SolveSettings set;
        solve_settings_default(&set);
        set.max_outer = 1;
        set.max_linear = 2;
        SolveStats ss;
        g_probe_projected = -1;
        problem_initial_guess(&f.pb, dv);
        if (!st) st = solver_solve(s, &f.pb, &set, dv, &ss, NULL, NULL, NULL);
        CHECK(st == MPM_OK && g_probe_projected == want[k], "%s: inverse approximation set up on a %s tangent", spec[k],
              g_probe_projected == 1 ? "projected" : g_probe_projected == 0 ? "unprojected" : "missing");
        solver_destroy(s);
        free(dv);
        fixture_free(&f);
    }
}

/* ---- 5. semi-implicit ---- */

static void semi_implicit(void)
{
    FixtureOptions o;
    fixture_default(&o);
    o.per_axis = 10;
    o.F_noise = 1e-4;
    o.v_noise = 1e-3;
    o.C_noise = 1e-3;
    o.two_materials = 1;
    o.gravity[1] = -9.81;
    o.dt = 1e-3;
    Fixture f;
    int st = fixture_build(&f, &o);
    CHECK(st == MPM_OK, "fixture: %s", mpm_last_error());
    if (st) return;
    StepProblem *pb = &f.pb;
    const double zero[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    for (int i = 0; i < pb->n_nodes; ++i) {
        const int *c = f.g.coord + 3 * (size_t)i;
        if (c[1] <= 10) problem_set_dirichlet(pb, i, zero, NULL);
        else if (c[0] <= 10) problem_set_dirichlet(pb, i, zero, up);
    }
    problem_finish_dirichlet(pb);
    const int n = pb->n_nodes;
    const size_t len = 3 * (size_t)n;
    double *dv0 = malloc(sizeof(double) * len), *lin = malloc(sizeof(double) * len), *g = malloc(sizeof(double) * len),
           *p = malloc(sizeof(double) * len), *t = malloc(sizeof(double) * len), *dv = malloc(sizeof(double) * len),
           *D = malloc(sizeof(double) * 9 * (size_t)n), *ex = malloc(sizeof(double) * len);
    problem_initial_guess(pb, dv0);
    Bsr H = {0};
    InvApprox *chol = NULL;
    st = inv_create(registry_find_inverse("cholmod"), NULL, &chol);
    for (int variant = 0; variant < 2 && !st; ++variant) {
        /* the exact Newton step from the linearisation point */
        for (size_t k = 0; k < len; ++k) t[k] = -f.g.v[k];
        if (variant == 0) solve_keep_dirichlet(pb, dv0, t, lin, p);
        else vec_copy(len, dv0, lin);
        problem_energy(pb, lin);
        problem_gradient(pb, lin, g);
        st = factor_true_hessian(pb, &H, D, chol);
        if (!st) {
            vec_scale(len, -1.0, g);
            st = inv_apply(chol, g, p);
        }
        CHECK(st == MPM_OK, "exact Newton step: %s", mpm_last_error());
        if (st) break;
        problem_project(pb, p);
        for (size_t k = 0; k < len; ++k) ex[k] = lin[k] + p[k];

        Solver *si = NULL;
        st = solver_from_spec(variant == 0 ? "semi-implicit:rtol=1e-12" : "semi-implicit:rtol=1e-12,linearize=guess",
                              NULL, 0, &si);
        SolveSettings set;
        solve_settings_default(&set);
        SolveStats ss;
        vec_copy(len, dv0, dv);
        if (!st) st = solver_solve(si, pb, &set, dv, &ss, NULL, NULL, NULL);
        CHECK(st == MPM_OK && ss.status == SOLVE_CONVERGED && ss.outer_iters == 1 && ss.linear_iters > 0,
              "semi-implicit: status %s (%s), %d / %ld iterations", solve_status_name(ss.status), ss.reason,
              ss.outer_iters, ss.linear_iters);
        for (size_t k = 0; k < len; ++k) t[k] = dv[k] - ex[k];
        double rel = vec_norm(len, t) / vec_norm(len, p);
        CHECK(rel < 1e-8, "%s: |dv - Newton step| / |step| = %.3e", variant ? "linearize=guess" : "at x^n", rel);
        problem_energy(pb, dv);
        problem_gradient(pb, dv, g);
        CHECK(ss.residual == problem_cn_residual(pb, g), "residual column %.6e, CN residual of dv %.6e", ss.residual,
              problem_cn_residual(pb, g));
        printf("semi-implicit (%s): %ld MINRES iterations, equals the exact Newton step to %.2e\n",
               variant ? "linearize=guess" : "at x^n", ss.linear_iters, rel);
        if (variant == 0) {
            /* a linear problem: one Newton step is (nearly) the solution */
            Solver *ref = NULL;
            SolveSettings rs;
            solve_settings_default(&rs);
            rs.eps = 1e-12;
            double *dvr = t;
            problem_initial_guess(pb, dvr);
            if (!st) st = solver_from_spec("pn-cholmod", NULL, 0, &ref);
            SolveStats sr;
            if (!st) st = solver_solve(ref, pb, &rs, dvr, &sr, NULL, NULL, NULL);
            for (size_t k = 0; k < len; ++k) g[k] = dv[k] - dvr[k], D[k] = dvr[k] - lin[k];
            double rs_rel = vec_norm(len, g) / vec_norm(len, D);
            CHECK(st == MPM_OK && rs_rel < 1e-3, "small deformation: one step vs the solution %.3e", rs_rel);
            printf("  one step vs the converged nonlinear solution: %.2e of the step\n", rs_rel);
            solver_destroy(ref);
        }
        solver_destroy(si);
    }
    inv_destroy(chol);
    bsr_free(&H);
    free(dv0), free(lin), free(g), free(p), free(t), free(dv), free(D), free(ex);
    fixture_free(&f);
}

int main(void)
{
    g_wolfe = line_search_find("wolfe");
    CHECK(g_wolfe != NULL, "the wolfe line search is registered");
    if (!g_wolfe) return test_summary("test_gast15");
    rest_diagonal();
    downhill();
    wolfe_steps();
    gast15_scene("stretched-box", 3.6, 1e-3);
    gast15_scene("bar3", 4.3, 1e-3);
    tangents();
    first_cg("gast15-hot", 1, PCG_RELATIVE, 0);
    first_cg("gast15:initial_guess=given", 0, PCG_RELATIVE_L2, 0);
    first_cg("gast15:initial_guess=given,stop=cn", 0, PCG_RELATIVE_L2, 1);
    semi_implicit();
    return test_summary("test_gast15");
}
