/* floor: driver */
/* Multigrid V-cycles as preconditioners of a real step problem with sticky
 * colliders and a stiff material: the first step of `wheel` (aluminium,
 * E = 6.9e10 Pa, clamped by the ground and touched by the pusher) at a
 * coarse scale.
 *
 * With an accurate coarse solve (coarse_tol=1e-6; the default 1/2 rule makes
 * the V-cycle vary with its input) a V-cycle V is, to that accuracy, a fixed SPD
 * map, and V H is similar to the SPD V^1/2 H V^1/2: its eigenvalues are real
 * and positive. For a Galerkin hierarchy (coarse matrices R A P) with
 * symmetric GS smoothing they lie in (0, 1]; the rediscretised baseline GMG
 * has no such bound, but a usable one stays within a small factor of 1. The
 * largest is estimated by power iteration on V H in the H inner product (a
 * Rayleigh quotient, so never above the true value): at most 1 + 1e-3 for
 * the linear and quadratic Galerkin hierarchies, below 10 for the GMG. A coarse level whose residual is not projected at its
 * Dirichlet nodes turns force-like residual entries into velocity
 * corrections through its identity rows, off by m_I + dt^2 k_I (~1e4 here),
 * and lambda_max explodes: coarse_bc_project=0 must show it, so the check
 * can fail. */
#include <math.h>
#include <omp.h>
#include <stdlib.h>

#include "core/step.h"
#include "core/vec.h"
#include "core/scene/scene_load.h"
#include "experiments/driver/registry.h"
#include "solvers/solver.h"
#include "tests/common/testutil.h"

static void spmv_op(const void *ctx, const double *x, double *y) { bsr_spmv((const Bsr *)ctx, x, y); }
static void project_op(const void *ctx, double *v) { problem_project((const StepProblem *)ctx, v); }

static double lambda_max_VH(const char *solver_name, const char *extra_opt)
{
    Scene sc;
    SceneLoadOptions lo = {.scale = 5.2};
    if (scene_load("wheel", &lo, &sc)) return NAN;
    Simulation sim;
    sim_init(&sim, &sc);
    step_begin(&sim);
    StepProblem *pb = &sim.pb;
    const int n = pb->n_nodes;
    const size_t len = 3 * (size_t)n;
    double *dv = malloc(sizeof(double) * len), *x = malloc(sizeof(double) * len), *y = malloc(sizeof(double) * len),
           *z = malloc(sizeof(double) * len);
    problem_initial_guess(pb, dv);
    problem_energy(pb, dv);
    problem_tangent(pb, 1);

    const char *user[2] = {"coarse_tol=1e-6", extra_opt};
    Solver *s = NULL;
    Bsr H = {0};
    double *diag = malloc(sizeof(double) * 9 * (size_t)n);
    double lambda = NAN;
    if (solver_from_spec(solver_name, user, extra_opt ? 2 : 1, &s) || problem_assemble(pb, &H)) goto done;
    bsr_diagonal(&H, diag);
    LinearOp op = {n, spmv_op, &H};
    Projection proj = {project_op, pb};
    InvSetupInput in = {.n_nodes = n, .H = &H, .diag = diag, .coord = pb->grid->coord,
                        .coloring = &pb->grid->coloring, .op = &op, .proj = &proj, .problem = pb};
    if (inv_setup(s->inv, &in)) goto done;
    CHECK(pb->n_dirichlet > 0, "wheel has sticky nodes (%d)", pb->n_dirichlet);

    unsigned long long rs = 11;
    for (size_t i = 0; i < len; ++i) x[i] = test_uniform(&rs, -1, 1);
    problem_project(pb, x);
    for (int it = 0; it < 15; ++it) {
        bsr_spmv(&H, x, y);                    /* y = H x */
        inv_apply(s->inv, y, z);               /* z = V H x */
        problem_project(pb, z);
        /* Rayleigh quotient in the H inner product: x^T H (V H x) / x^T H x */
        double num = vec_dot(len, y, z), den = vec_dot(len, y, x);
        lambda = num / den;
        double nz = vec_norm(len, z);
        for (size_t i = 0; i < len; ++i) x[i] = z[i] / nz;
    }
done:
    solver_destroy(s);
    bsr_free(&H);
    free(diag);
    free(dv), free(x), free(y), free(z);
    sim_free(&sim);
    scene_free(&sc);
    return lambda;
}

int main(void)
{
    /* thousands of coarse PCG iterations on ~200 nodes: one thread is faster */
    omp_set_num_threads(1);
    static const struct {
        const char *preset;
        double bound;
    } cases[] = {{"pn-mgpcg", 1.0 + 1e-3}, {"hot-quadratic", 1.0 + 1e-3}, {"pn-gmgpcg", 10.0}};
    for (int k = 0; k < 3; ++k) {
        double lam = lambda_max_VH(cases[k].preset, NULL);
        printf("wheel, first step: lambda_max(V H) of %-14s %.4f\n", cases[k].preset, lam);
        CHECK(lam > 0.5 && lam < cases[k].bound, "%s: lambda_max(V H) = %.6g, expected in (0.5, %g)", cases[k].preset,
              lam, cases[k].bound);
    }
    double bad = lambda_max_VH("pn-gmgpcg", "coarse_bc_project=0");
    printf("wheel, first step: lambda_max(V H) of pn-gmgpcg without the coarse BC projection %.4g\n", bad);
    CHECK(bad > 100.0, "without the coarse residual projection the GMG V-cycle is mis-scaled (%.4g)", bad);
    return test_summary("test_mg_scene");
}
