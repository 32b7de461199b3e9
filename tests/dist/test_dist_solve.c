/* floor: driver */
/* needs: MPM_WITH_PETSC */
/* Solvers across ranks: the first step of bar3 split over the ranks and
 * solved with every solver reduction summed over them
 * (vec_sum_over_ranks), against the whole scene solved on one process, for
 * matrix-free projected Newton with block-Jacobi PCG (pn-pcg-mf) and L-BFGS
 * with a Jacobi initial inverse (lbfgs:jacobi). Checked: both converge;
 * the same outer and linear iteration counts (the same operations, the
 * sums in another order: counts may differ only where a residual lands
 * within round-off of the threshold, which this case does not); dv on
 * every owned node within 1e-8 of the whole scene's, relative to its
 * largest entry (both solves stop at CN 1e-7; L-BFGS's Jacobi takes its
 * diagonal from problem_diagonal across ranks and from the assembled
 * matrix on one process, which differ in rounding: 9e-10 at one rank);
 * the final CN residual within 1e-6 relative. Serially and, from
 * tests/dist/test_dist_mpi.sh, on 2 and 3 ranks. An assembled solver
 * (pn-pcg) is refused with one line on every rank. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/petsc_comm.h"
#include "core/dist/dist_sim.h"
#include "core/error.h"
#include "core/scene/scene_load.h"
#include "core/step.h"
#include "core/vec.h"
#include "experiments/driver/registry.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

static void check_solver(const CommOps *comm, const char *spec)
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
    CHECK(ss.outer_iters == SS.outer_iters && ss.linear_iters == SS.linear_iters,
          "%s rank %d: %ld outer and %ld linear iterations, the whole scene %ld and %ld", spec, comm->rank,
          (long)ss.outer_iters, (long)ss.linear_iters, (long)SS.outer_iters, (long)SS.linear_iters);
    double scale = 0, worst = 0;
    for (int k = 0; k < 3 * N; ++k) scale = fmax(scale, fabs(DV[k]));
    for (int i = 0; i < n; ++i) {
        if (!sim.dist.owned[i]) continue;
        int I = grid_lookup(&whole.sim.grid, sim.grid.coord + 3 * (size_t)i);
        for (int d = 0; d < 3 && I >= 0; ++d) worst = fmax(worst, fabs(dv[3 * i + d] - DV[3 * I + d]) / scale);
    }
    CHECK(worst <= 1e-8, "%s rank %d: dv differs by %.3g relative", spec, comm->rank, worst);
    CHECK(fabs(ss.residual - SS.residual) <= 1e-6 * SS.residual, "%s rank %d: CN residual %.9g, the whole scene's %.9g",
          spec, comm->rank, ss.residual, SS.residual);
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

/* pn-pcg assembles its Hessian, which is not distributed: every rank refuses it */
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
    if (!st) st = solver_from_spec("pn-pcg", NULL, 0, &solver);
    CHECK(st == MPM_OK, "pn-pcg rank %d: set-up: %s", comm->rank, mpm_last_error());
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
        CHECK(st == MPM_EINPUT && strstr(mpm_last_error(), "not distributed"), "pn-pcg rank %d: %d %s (%ld outer, %s)",
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
    check_solver(&comm, "pn-pcg-mf");
    check_solver(&comm, "lbfgs:jacobi");
    check_refused(&comm);
    char name[64];
    snprintf(name, sizeof name, "test_dist_solve (rank %d of %d)", comm.rank, comm.ranks);
    comm.close(comm.ctx);
    return test_summary(name);
}
