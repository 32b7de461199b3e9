/* floor: driver */
/* The worked example of docs/solvers.md ("Adding a solver"),
 * docs/examples/trace_jacobi.c, compiled here as it is: it must build
 * without warnings, honour the InvApprox contract (apply before setup
 * refused, the map it claims: z_i = omega 3 / trace(D_i) r_i, symmetric and
 * positive), reject a bad option, and, composed with projected Newton and
 * with L-BFGS by solver_create, solve a step problem to eps. */
#include "docs/examples/trace_jacobi.c"

#include <stdio.h>
#include <string.h>

#include "core/vec.h"
#include "experiments/driver/registry.h"
#include "solvers/solver.h"
#include "tests/common/fixture.h"
#include "tests/common/testutil.h"


static void spmv_op(const void *ctx, const double *x, double *y) { bsr_spmv((const Bsr *)ctx, x, y); }
static void project_op(const void *ctx, double *v) { problem_project((const StepProblem *)ctx, v); }

/* Creates the example through inv_create with "key=value,..." options. */
static int create(const char *options, InvApprox **out)
{
    SolverOptions o = {0};
    int st = solver_opts_set_list(&o, options, "test");
    return st ? st : inv_create(&inv_trace_jacobi_ops, &o, out);
}

/* Solves the fixture's step problem with OUTER:trace-jacobi; returns the status. */
static SolveStatus solve_with(const char *outer, StepProblem *pb, const double *dv0, double *residual, int *iters)
{
    Solver *s = NULL;
    SolverOptions o = {0};
    char name[64];
    snprintf(name, sizeof name, "%s:trace-jacobi", outer);
    int st = solver_create(name, registry_find_outer(outer), &inv_trace_jacobi_ops, &o, &s);
    CHECK(st == MPM_OK, "%s: solver_create: %s", name, mpm_last_error());
    if (st) return SOLVE_FAILED;
    SolveSettings set;
    solve_settings_default(&set);
    set.eps = 1e-7;
    size_t len = 3 * (size_t)pb->n_nodes;
    double *dv = malloc(sizeof(double) * (len + 1));
    memcpy(dv, dv0, sizeof(double) * len);
    SolveStats ss;
    memset(&ss, 0, sizeof ss);
    st = solver_solve(s, pb, &set, dv, &ss, NULL, NULL, NULL);
    CHECK(st == MPM_OK, "%s: solver_solve: %s", name, mpm_last_error());
    printf("%s: %s, %d outer, %ld linear iterations, residual %.3e\n", name, solve_status_name(ss.status),
           ss.outer_iters, ss.linear_iters, ss.residual);
    *residual = ss.residual;
    *iters = ss.outer_iters;
    free(dv);
    solver_destroy(s);
    return ss.status;
}

int main(void)
{
    /* options: the default, a valid one, invalid values and an unknown key */
    InvApprox *M = NULL;
    CHECK(create("", &M) == MPM_OK, "default options: %s", mpm_last_error());
    CHECK(M && M->caps == (INV_MATRIX_FREE | INV_SYMMETRIC | INV_POSITIVE), "capabilities");
    double r3[3] = {1, 2, 3}, z3[3];
    mpm_clear_error();
    CHECK(M && inv_apply(M, r3, z3) != MPM_OK, "apply before setup refused");
    inv_destroy(M);
    M = NULL;
    mpm_clear_error();
    CHECK(create("omega=0", &M) == MPM_EINPUT && !M, "omega=0 refused");
    mpm_clear_error();
    CHECK(create("omega=2.5", &M) == MPM_EINPUT && !M, "omega=2.5 refused");
    mpm_clear_error();
    Solver *bad = NULL;
    SolverOptions unknown = {0};
    solver_opts_set_list(&unknown, "omga=1", "test");
    CHECK(solver_create("pn:trace-jacobi", registry_find_outer("pn"), &inv_trace_jacobi_ops, &unknown, &bad) ==
              MPM_EINPUT,
          "a misspelt option is an error");
    printf("unknown option: %s\n", mpm_last_error());
    solver_destroy(bad);
    mpm_clear_error();

    /* a small step problem (two materials, sticky and slip nodes) */
    Fixture f;
    FixtureOptions fo;
    fixture_default(&fo);
    fo.per_axis = 10;
    fo.two_materials = 1;
    fo.gravity[1] = -9.81;
    int st = fixture_build(&f, &fo);
    CHECK(st == MPM_OK, "fixture: %s", mpm_last_error());
    if (st) return test_summary("test_example_inverse");
    StepProblem *pb = &f.pb;
    const double zero[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    for (int i = 0; i < pb->n_nodes; ++i) {
        const int *c = f.g.coord + 3 * (size_t)i;
        if ((c[0] + 2 * c[1] + 3 * c[2]) % 11 == 0) problem_set_dirichlet(pb, i, zero, NULL);
        else if ((c[0] + c[1] + c[2]) % 13 == 0) problem_set_dirichlet(pb, i, zero, up);
    }
    problem_finish_dirichlet(pb);
    int n = pb->n_nodes;
    size_t len = 3 * (size_t)n;
    double *dv0 = malloc(sizeof(double) * len), *diag = malloc(sizeof(double) * 9 * (size_t)n);
    double *x = malloc(sizeof(double) * len), *y = malloc(sizeof(double) * len);
    double *Mx = malloc(sizeof(double) * len), *My = malloc(sizeof(double) * len);
    problem_initial_guess(pb, dv0);
    problem_energy(pb, dv0);
    Bsr H = {0};
    st = problem_tangent(pb, 1);
    st = st ? st : problem_assemble(pb, &H);
    CHECK(st == MPM_OK, "assembly: %s", mpm_last_error());
    bsr_diagonal(&H, diag);
    LinearOp op = {n, spmv_op, &H};
    Projection proj = {project_op, pb};
    InvSetupInput in = {.n_nodes = n, .H = NULL, .diag = diag, .coord = f.g.coord, .coloring = &f.g.coloring,
                        .op = &op, .proj = &proj, .problem = pb};

    /* the map it claims, symmetric and positive */
    CHECK(create("omega=0.8", &M) == MPM_OK, "omega=0.8: %s", mpm_last_error());
    CHECK(inv_setup(M, &in) == MPM_OK, "matrix-free setup: %s", mpm_last_error());
    unsigned long long seed = 7;
    for (size_t k = 0; k < len; ++k) x[k] = test_uniform(&seed, -1, 1), y[k] = test_uniform(&seed, -1, 1);
    problem_project(pb, x);
    problem_project(pb, y);
    CHECK(inv_apply(M, x, Mx) == MPM_OK && inv_apply(M, y, My) == MPM_OK, "apply");
    double worst = 0;
    for (int i = 0; i < n; ++i) {
        const double *D = diag + 9 * (size_t)i;
        double s = 0.8 * 3.0 / (D[0] + D[4] + D[8]);
        for (int k = 0; k < 3; ++k) worst = fmax(worst, rel_diff(Mx[3 * i + k], s * x[3 * i + k], 1e-300));
    }
    CHECK(worst < 1e-15, "z_i = omega 3 / trace(D_i) r_i (worst relative difference %.2e)", worst);
    double yMx = vec_dot(len, y, Mx), xMy = vec_dot(len, x, My), xMx = vec_dot(len, x, Mx);
    CHECK(rel_diff(yMx, xMy, 1e-300) < 1e-12, "symmetric: %.17g vs %.17g", yMx, xMy);
    CHECK(xMx > 0, "positive: x^T M x = %g", xMx);
    InvView v = {0};
    inv_view(M, stdout, &v);
    CHECK(v.n_stats == 1 && !strcmp(v.stat[0].key, "nodes") && v.stat[0].value == n, "view: nodes");
    inv_destroy(M);

    /* composed with projected Newton and L-BFGS: solves to eps */
    double res;
    int iters;
    CHECK(solve_with("pn", pb, dv0, &res, &iters) == SOLVE_CONVERGED && res < 1e-7 && iters > 0,
          "pn:trace-jacobi converges (residual %g)", res);
    CHECK(solve_with("lbfgs", pb, dv0, &res, &iters) == SOLVE_CONVERGED && res < 1e-7 && iters > 0,
          "lbfgs:trace-jacobi converges (residual %g)", res);

    bsr_free(&H);
    free(dv0), free(diag), free(x), free(y), free(Mx), free(My);
    fixture_free(&f);
    return test_summary("test_example_inverse");
}
