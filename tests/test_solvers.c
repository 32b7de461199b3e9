/* Solver conformance on the same step problem (SPEC 4, 5, 7):
 *  - every registered solver reaches the CN tolerance eps = 1e-7 on the first
 *    step of `stretched-box`, and PN solvers lower E monotonically;
 *  - all of them reach the same dv within a bound implied by the tolerance;
 *  - the same solver twice with the same thread count gives identical
 *    iteration counts and residuals (determinism);
 *  - HOT needs far fewer L-BFGS iterations than LBFGS-H on the stretched box
 *    (HOT Fig. 18: 25 vs 106 at paper size; we assert a ratio >= 3).
 *
 * Agreement bound, in the mass norm |e|_M = sqrt(sum_i m_i |e_i|^2) (the
 * kinetic-energy norm, so the bound is not swamped by nearly empty nodes):
 * near the minimiser H >= M (the elastic part of the projected Hessian is
 * positive semidefinite), so |dv - dv*|_M <= |g|_{M^-1}. The CN rule
 * s < eps bounds sum_i |g_i|^2 / kappa_i^2 < n eps^2, hence
 * |g|_{M^-1} <= sqrt(n) eps max_i kappa_i / sqrt(m_i). Two converged solvers
 * differ by at most twice that. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/step.h"
#include "core/vec.h"
#include "experiments/registry.h"
#include "tests/testutil.h"

typedef struct {
    double last;
    int monotone;
    int iters;
} EnergyTrace;

static void trace_hook(void *ctx, int iter, double elapsed, double residual, double energy)
{
    EnergyTrace *t = ctx;
    if (iter > 0 && energy > t->last) t->monotone = 0;
    t->last = energy;
    t->iters = iter;
}

typedef struct {
    double *dv;
    SolveStats st;
    int monotone;
} Outcome;

typedef struct {
    int n;
    double kappa_over_sqrt_m; /* max_i kappa_i / sqrt(m_i) */
    double *mass;
} ProblemInfo;

static int solve_first_step(const char *scene_name, const SceneOverride *ov, int n_ov, double scale,
                            const char *solver, Outcome *out, ProblemInfo *keep)
{
    Scene sc;
    SceneLoadOptions lo = {scale, ov, n_ov, NULL};
    if (scene_load(scene_name, &lo, &sc)) return 1;
    Simulation sim;
    sim_init(&sim, &sc);
    step_begin(&sim);
    int n = sim.pb.n_nodes;
    out->dv = calloc(3 * (size_t)n, sizeof(double));
    problem_initial_guess(&sim.pb, out->dv);
    const SolverPreset *pre = registry_find(solver);
    SolverOptions so;
    registry_options(pre, NULL, 0, &so);
    Solver *s = NULL;
    solver_create(pre, &so, &s);
    SolveSettings set;
    solve_settings_default(&set);
    EnergyTrace tr = {0, 1, 0};
    int st = solver_solve(s, &sim.pb, &set, out->dv, &out->st, trace_hook, &tr);
    out->monotone = tr.monotone;
    solver_destroy(s);
    if (keep) {
        /* the caller needs masses and kappa of this problem for the bound */
        double kmax = 0;
        for (int i = 0; i < n; ++i) kmax = fmax(kmax, sim.pb.kappa[i] / sqrt(sim.grid.mass[i]));
        keep->kappa_over_sqrt_m = kmax;
        keep->n = n;
        keep->mass = malloc(sizeof(double) * (size_t)n);
        memcpy(keep->mass, sim.grid.mass, sizeof(double) * (size_t)n);
    }
    sim_free(&sim);
    scene_free(&sc);
    return st;
}

static void agreement(const char *scene, const SceneOverride *ov, int n_ov, double scale)
{
    int np = registry_count();
    Outcome *res = calloc((size_t)np, sizeof(Outcome));
    ProblemInfo info = {0, 0, NULL};
    for (int k = 0; k < np; ++k) {
        const SolverPreset *p = registry_get(k);
        int st = solve_first_step(scene, ov, n_ov, scale, p->name, &res[k], k == 0 ? &info : NULL);
        CHECK(st == 0, "%s on %s: solve returned %d", p->name, scene, st);
        CHECK(res[k].st.status == SOLVE_CONVERGED, "%s on %s: status %s, residual %.3e", p->name, scene,
              solve_status_name(res[k].st.status), res[k].st.residual);
        CHECK(res[k].st.residual < 1e-7, "%s on %s: residual %.3e < 1e-7", p->name, scene, res[k].st.residual);
        if (p->method == METHOD_PN) CHECK(res[k].monotone, "%s on %s: energy decreases monotonically", p->name, scene);
        printf("%-14s %-14s outer %4d linear %6ld residual %.3e\n", scene, p->name, res[k].st.outer_iters,
               res[k].st.linear_iters, res[k].st.residual);
    }
    int n = info.n;
    double bound = 2.0 * sqrt((double)n) * 1e-7 * info.kappa_over_sqrt_m;
    for (int k = 1; k < np; ++k) {
        double diff = 0;
        for (int i = 0; i < 3 * n; ++i)
            diff += info.mass[i / 3] * (res[k].dv[i] - res[0].dv[i]) * (res[k].dv[i] - res[0].dv[i]);
        diff = sqrt(diff);
        CHECK(diff <= bound, "%s vs %s on %s: |dv difference|_M %.3e > bound %.3e", registry_get(k)->name,
              registry_get(0)->name, scene, diff, bound);
        printf("  %s vs %s: |ddv|_M = %.3e (bound %.3e)\n", registry_get(k)->name, registry_get(0)->name, diff, bound);
    }
    for (int k = 0; k < np; ++k) free(res[k].dv);
    free(res);
    free(info.mass);
}

static void hot_vs_lbfgs_h(void)
{
    Outcome h, l;
    solve_first_step("stretched-box", NULL, 0, 1.4, "hot", &h, NULL);
    solve_first_step("stretched-box", NULL, 0, 1.4, "lbfgs-h", &l, NULL);
    printf("stretched-box scale 1.4: hot %d outer, lbfgs-h %d outer\n", h.st.outer_iters, l.st.outer_iters);
    CHECK(h.st.status == SOLVE_CONVERGED && l.st.status == SOLVE_CONVERGED, "both converge");
    CHECK(l.st.outer_iters >= 3 * h.st.outer_iters, "HOT %d vs LBFGS-H %d outer iterations: ratio below 3",
          h.st.outer_iters, l.st.outer_iters);
    free(h.dv);
    free(l.dv);
}

static void determinism(void)
{
    Outcome a, b;
    solve_first_step("stretched-box", NULL, 0, 2.0, "pn-pcg", &a, NULL);
    solve_first_step("stretched-box", NULL, 0, 2.0, "pn-pcg", &b, NULL);
    CHECK(a.st.outer_iters == b.st.outer_iters && a.st.linear_iters == b.st.linear_iters,
          "same iteration counts twice (%d/%ld vs %d/%ld)", a.st.outer_iters, a.st.linear_iters, b.st.outer_iters,
          b.st.linear_iters);
    CHECK(a.st.residual == b.st.residual, "bitwise identical residual twice (%.17g vs %.17g)", a.st.residual,
          b.st.residual);
    free(a.dv);
    free(b.dv);
}

int main(void)
{
    agreement("stretched-box", NULL, 0, 2.0);
    SceneOverride stiff = {"materials.middle.E", "1e9"};
    agreement("bar3", &stiff, 1, 4.0);
    determinism();
    hot_vs_lbfgs_h();
    return test_summary("test_solvers");
}
