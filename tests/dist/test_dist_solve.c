/* floor: driver */
/* needs: MPM_WITH_PETSC */
/* Solvers across ranks: the first step of bar3 split over the ranks and
 * solved with every solver reduction summed over them
 * (vec_sum_over_ranks), against the whole scene solved on one process.
 *
 * The same operations as one process's, sums in another order: projected
 * Newton with block-Jacobi PCG, matrix-free (pn-pcg-mf) and on the ranks'
 * assembled parts (pn-pcg), and L-BFGS with a Jacobi initial inverse
 * (lbfgs:jacobi). Checked: they converge with the same outer and linear
 * iteration counts (counts could differ only where a residual lands within
 * round-off of the threshold, which this case does not); dv on every
 * owned node within 1e-8 of the whole scene's, relative to its largest
 * entry (measured: 1e-11 on 2 ranks); the final CN residual within 1e-6
 * relative.
 *
 * PETSc's preconditioners on its parallel matrix (pn-gamg-pcg,
 * lbfgs-gamg, BoomerAMG and ML through PETSc): they aggregate within each
 * rank, so they are other preconditioners than one process's. Checked:
 * they converge, the outer iterations within 2 of one process's and the
 * linear ones at most twice (+4). HOT through PETSc (hot-petsc, with its
 * coloured SGS or PETSc's smoother): on one rank the one-process hierarchy
 * (the same iterations, dv within 1e-8); on more, its Gauss-Seidel sweeps
 * each rank's rows, so within the same band.
 *
 * Every solver: the ranks' dv gathered into the whole scene's nodes has a
 * CN residual below eps on the whole scene's problem (the split solved the
 * real problem). PETSc's parallel matrix times a field equals the ranks'
 * completed product (problem_assembled_product) to 1e-13 (aij and baij).
 * A solver whose inverse has no form across ranks (pn-sgs-pcg) is refused
 * with one line on every rank. Serially and, from tests/dist/test_dist_mpi.sh,
 * on 2 and 3 ranks. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/petsc.h"
#include "adapters/petsc_comm.h"
#include "core/dist/dist_sim.h"
#include "core/error.h"
#include "core/scene/scene_load.h"
#include "core/step.h"
#include "core/vec.h"
#include "experiments/driver/registry.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

/* exact: the same operations as on one process, sums in another order;
 * else the preconditioner itself differs with the split (an algebraic
 * multigrid aggregates within each rank) */
static void check_solver(const CommOps *comm, const char *spec, int exact)
{
    SceneStep whole;
    Scene sc;
    Simulation sim;
    Solver *solver = NULL, *whole_solver = NULL; /* one each: a solver keeps state between solves */
    SceneLoadOptions lo = {.scale = 4.0};
    vec_sum_over_ranks(NULL); /* the whole scene, on every rank alike */
    int st = scene_step_open(&whole, "bar3", 4.0);
    int loaded = !st && !(st = scene_load("bar3", &lo, &sc));
    int started = loaded && !(st = sim_init(&sim, &sc));
    if (!st) st = sim_distribute(&sim, comm);
    if (!st) st = step_begin(&sim);
    if (!st) st = solver_from_spec(spec, NULL, 0, &solver);
    if (!st) st = solver_from_spec(spec, NULL, 0, &whole_solver);
    CHECK(st == MPM_OK, "%s rank %d: set-up: %s", spec, comm->rank, mpm_last_error());
    if (st) goto done;
    SolveSettings set;
    solve_settings_default(&set);
    const int N = whole.sim.pb.n_nodes, n = sim.pb.n_nodes;
    double *DV = malloc(sizeof(double) * 3 * (size_t)N), *dv = malloc(sizeof(double) * 3 * (size_t)n);
    SolveStats SS, ss;
    problem_initial_guess(&whole.sim.pb, DV);
    st = solver_solve(whole_solver, &whole.sim.pb, &set, DV, &SS, NULL, NULL, NULL);
    CHECK(st == MPM_OK && SS.status == SOLVE_CONVERGED, "%s: the whole scene's solve: %s %s", spec, mpm_last_error(),
          SS.reason);
    vec_sum_over_ranks(comm);
    problem_initial_guess(&sim.pb, dv);
    for (int i = 0; i < n; ++i) /* the solver's vectors hold zeros at ghosts */
        if (!sim.dist.owned[i]) memset(dv + 3 * i, 0, 3 * sizeof(double));
    st = solver_solve(solver, &sim.pb, &set, dv, &ss, NULL, NULL, NULL);
    vec_sum_over_ranks(NULL);
    CHECK(st == MPM_OK && ss.status == SOLVE_CONVERGED, "%s rank %d: the distributed solve: %s %s", spec, comm->rank,
          mpm_last_error(), ss.reason);
    if (exact)
        CHECK(ss.outer_iters == SS.outer_iters && ss.linear_iters == SS.linear_iters,
              "%s rank %d: %ld outer and %ld linear iterations, the whole scene %ld and %ld", spec, comm->rank,
              (long)ss.outer_iters, (long)ss.linear_iters, (long)SS.outer_iters, (long)SS.linear_iters);
    else
        CHECK(labs(ss.outer_iters - SS.outer_iters) <= 2 && ss.linear_iters <= 2 * SS.linear_iters + 4,
              "%s rank %d: %ld outer and %ld linear iterations, the whole scene %ld and %ld (band: outer +-2, "
              "linear at most 2x+4)",
              spec, comm->rank, (long)ss.outer_iters, (long)ss.linear_iters, (long)SS.outer_iters,
              (long)SS.linear_iters);
    /* the ranks' dv gathered into the whole scene's nodes (each owned once)
     * solves the whole scene's problem: its CN residual there is below eps */
    double *gathered = calloc(3 * (size_t)N, sizeof(double));
    int found = 1;
    for (int i = 0; i < n; ++i) {
        if (!sim.dist.owned[i]) continue;
        int I = grid_lookup(&whole.sim.grid, sim.grid.coord + 3 * (size_t)i);
        if (I < 0) found = 0;
        else memcpy(gathered + 3 * (size_t)I, dv + 3 * (size_t)i, 3 * sizeof(double));
    }
    CHECK(found, "%s rank %d: an owned node the whole scene lacks", spec, comm->rank);
    CHECK(comm->sum(comm->ctx, gathered, 3 * N) == MPM_OK, "%s: gathering dv", spec);
    double *G = malloc(sizeof(double) * 3 * (size_t)N);
    problem_energy(&whole.sim.pb, gathered);
    problem_gradient(&whole.sim.pb, gathered, G);
    const double cn = problem_cn_residual(&whole.sim.pb, G);
    CHECK(cn < set.eps, "%s rank %d: the gathered dv's CN residual on the whole scene %.3g, eps %g", spec, comm->rank,
          cn, set.eps);
    free(gathered), free(G);
    double scale = 0, worst = 0;
    for (int k = 0; k < 3 * N; ++k) scale = fmax(scale, fabs(DV[k]));
    for (int i = 0; i < n; ++i) {
        if (!sim.dist.owned[i]) continue;
        int I = grid_lookup(&whole.sim.grid, sim.grid.coord + 3 * (size_t)i);
        for (int d = 0; d < 3 && I >= 0; ++d) worst = fmax(worst, fabs(dv[3 * i + d] - DV[3 * I + d]) / scale);
    }
    if (exact) {
        CHECK(worst <= 1e-8, "%s rank %d: dv differs by %.3g relative", spec, comm->rank, worst);
        CHECK(fabs(ss.residual - SS.residual) <= 1e-6 * SS.residual,
              "%s rank %d: CN residual %.9g, the whole scene's %.9g", spec, comm->rank, ss.residual, SS.residual);
    }
    if (!comm->rank) printf("%s: %ld outer, %ld linear; dv within %.2g of the whole scene's\n", spec,
                            (long)ss.outer_iters, (long)ss.linear_iters, worst);
    free(DV), free(dv);
done:
    if (solver) solver_destroy(solver);
    if (whole_solver) solver_destroy(whole_solver);
    if (started) sim_free(&sim);
    if (loaded) scene_free(&sc);
    scene_step_close(&whole);
}

/* PETSc's parallel matrix built from every rank's part of the Hessian
 * (ghost rows through its assembly) times a field equals the ranks' own
 * assembled product (problem_assembled_product, checked against the whole
 * scene by test_dist_problem) to round-off, with aij and baij storage. */
static void check_petsc_matrix(const CommOps *comm, const char *spec)
{
    Scene sc;
    Simulation sim;
    SceneLoadOptions lo = {.scale = 4.0};
    InvApprox *M = NULL;
    Bsr H = {0};
    SolverOptions opt;
    memset(&opt, 0, sizeof opt);
    int st = solver_opts_set_list(&opt, spec, "test");
    int loaded = !st && !(st = scene_load("bar3", &lo, &sc));
    int started = loaded && !(st = sim_init(&sim, &sc));
    if (!st) st = sim_distribute(&sim, comm);
    if (!st) st = step_begin(&sim);
    if (!st) st = inv_create(&inv_petsc_ops, &opt, &M);
    const int n = started ? sim.pb.n_nodes : 0;
    double *x = malloc(sizeof(double) * 3 * (size_t)(n + 1)), *y = malloc(sizeof(double) * 3 * (size_t)(n + 1));
    double *Y = malloc(sizeof(double) * 3 * (size_t)(n + 1)), *diag = malloc(sizeof(double) * 9 * (size_t)(n + 1));
    CHECK(st == MPM_OK, "petsc matrix (%s) rank %d: set-up: %s", spec, comm->rank, mpm_last_error());
    if (st) goto done;
    double *dv = x;
    problem_initial_guess(&sim.pb, dv);
    for (int i = 0; i < n; ++i)
        if (!sim.dist.owned[i]) memset(dv + 3 * i, 0, 3 * sizeof(double));
    problem_energy(&sim.pb, dv);
    st = problem_tangent(&sim.pb, 1);
    if (!st) st = problem_assemble(&sim.pb, &H);
    problem_assembled_diagonal(&sim.pb, &H, diag);
    InvSetupInput in = {.n_nodes = n, .H = &H, .diag = diag, .coord = sim.grid.coord, .comm = comm,
                        .owned = sim.dist.owned};
    if (!st) st = inv_setup(M, &in);
    CHECK(st == MPM_OK, "petsc matrix (%s) rank %d: setup: %s", spec, comm->rank, mpm_last_error());
    if (st) goto done;
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d) {
            const int *c = sim.grid.coord + 3 * (size_t)i;
            x[3 * i + d] = sim.dist.owned[i] ? sin(0.3 * c[0] + 0.7 * d) * cos(0.2 * c[1] - 0.1 * c[2]) : 0.0;
        }
    problem_assembled_product(&sim.pb, &H, x, Y);
    st = petsc_matvec(M, x, y);
    double scale = 0, worst = 0;
    for (int k = 0; k < 3 * n; ++k) scale = fmax(scale, fabs(Y[k]));
    for (int k = 0; k < 3 * n; ++k) worst = fmax(worst, fabs(y[k] - Y[k]));
    double both[2] = {scale, worst};
    comm->max(comm->ctx, both, 2);
    CHECK(st == MPM_OK && both[1] <= 1e-13 * both[0], "petsc matrix (%s) rank %d: |A x - H x| %.3g of %.3g: %s", spec,
          comm->rank, both[1], both[0], mpm_last_error());
    if (!comm->rank) printf("PETSc's parallel matrix (%s): A x within %.2g of H x (relative)\n", spec, both[1] / both[0]);
done:
    mpm_clear_error();
    if (M) inv_destroy(M);
    bsr_free(&H);
    free(x), free(y), free(Y), free(diag);
    if (started) sim_free(&sim);
    if (loaded) scene_free(&sc);
}

/* Gauss-Seidel sweeps one process's matrix: every rank refuses it */
static void check_refused(const CommOps *comm)
{
    Scene sc;
    Simulation sim;
    Solver *solver = NULL;
    SceneLoadOptions lo = {.scale = 4.0};
    int st = scene_load("bar3", &lo, &sc);
    int loaded = !st, started = loaded && !(st = sim_init(&sim, &sc));
    if (!st) st = sim_distribute(&sim, comm);
    if (!st) st = step_begin(&sim);
    if (!st) st = solver_from_spec("pn-sgs-pcg", NULL, 0, &solver);
    CHECK(st == MPM_OK, "pn-sgs-pcg rank %d: set-up: %s", comm->rank, mpm_last_error());
    if (!st) {
        SolveSettings set;
        solve_settings_default(&set);
        double *dv = calloc(3 * (size_t)sim.pb.n_nodes + 3, sizeof(double));
        problem_initial_guess(&sim.pb, dv);
        for (int i = 0; i < sim.pb.n_nodes; ++i)
            if (!sim.dist.owned[i]) memset(dv + 3 * i, 0, 3 * sizeof(double));
        SolveStats ss;
        vec_sum_over_ranks(comm);
        st = solver_solve(solver, &sim.pb, &set, dv, &ss, NULL, NULL, NULL);
        vec_sum_over_ranks(NULL);
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), "no form across ranks"), "pn-sgs-pcg rank %d: %d %s (%ld outer, %s)",
              comm->rank, st, mpm_last_error(), (long)ss.outer_iters, ss.reason);
        mpm_clear_error();
        free(dv);
    }
    if (solver) solver_destroy(solver);
    if (started) sim_free(&sim);
    if (loaded) scene_free(&sc);
}

int main(void)
{
    CommOps comm;
    int st = petsc_comm_open(&comm);
    CHECK(st == MPM_OK, "petsc_comm_open: %s", mpm_last_error());
    if (st) return test_summary("test_dist_solve");
    check_solver(&comm, "pn-pcg-mf", 1);
    check_solver(&comm, "lbfgs:jacobi", 1);
    check_solver(&comm, "pn-pcg", 1);
    check_solver(&comm, "pn-gamg-pcg", 0);
    check_solver(&comm, "lbfgs-gamg", 0);
    check_solver(&comm, "pn:petsc:pc_type=hypre", 0); /* BoomerAMG through PETSc's parallel matrix */
    check_solver(&comm, "pn:petsc:pc_type=ml", 0);
    /* HOT: its levels split over the ranks; one rank's is the one-process hierarchy */
    check_solver(&comm, "hot-petsc", comm.ranks == 1);
    check_solver(&comm, "hot-petsc:petsc_smoother=petsc", comm.ranks == 1);
    check_petsc_matrix(&comm, "");
    check_petsc_matrix(&comm, "petsc_mat_type=baij,pc_type=bjacobi"); /* GAMG takes no BAIJ in PETSc 3.18 */
    check_refused(&comm);
    char name[64];
    snprintf(name, sizeof name, "test_dist_solve (rank %d of %d)", comm.rank, comm.ranks);
    comm.close(comm.ctx);
    return test_summary(name);
}
