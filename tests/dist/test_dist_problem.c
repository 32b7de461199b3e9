/* floor: driver */
/* needs: MPM_WITH_PETSC */
/* The step problem of a scene split over ranks (core/dist/dist_sim.c and
 * the distributed parts of core/problem.c) against the same scene on one
 * process. Run as is it is one rank; tests/dist/test_dist_halo_mpi.sh runs
 * it under mpirun with 2 and 3 ranks.
 *
 * On bar3 (sticky ends) and on wheel (a moving slip collider), the first
 * step's time step is the same to the bit; for every owned node the mass,
 * the grid velocity, the CN scale and the constraint kind equal the whole
 * scene's; at a test field dv (ghost entries set to 1e30, which must never
 * be read: the halo copy replaces them) the energy, the gradient, H x and
 * the block diagonal equal the whole scene's to 1e-12 relative (the same
 * terms added in another order), and so do H x and the diagonal of the
 * rank's assembled part of the Hessian (problem_assembled_product and
 * _diagonal: ghost rows partial, completed at the owners), the ghosts of outgoing fields are zero
 * (identity blocks for the diagonal), and the CN residual and its
 * threshold tau agree. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/petsc_comm.h"
#include "core/dist/dist_sim.h"
#include "core/error.h"
#include "core/scene/scene_load.h"
#include "core/step.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

static double field(const int c[3], int d, double dx)
{
    return 0.01 * sin(0.7 * c[0] + 0.3 * d) * cos(0.5 * c[1]) + 0.02 * cos(0.9 * c[2] - d) * dx;
}

static double largest(const double *a, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; ++i) m = fmax(m, fabs(a[i]));
    return m > 0 ? m : 1;
}

/* the largest |local - whole| over owned nodes, relative to the whole's largest entry */
static double owned_diff(const Simulation *s, const Simulation *w, const double *local, const double *whole, int width)
{
    double scale = largest(whole, (size_t)width * w->grid.n), worst = 0;
    for (int i = 0; i < s->grid.n; ++i) {
        if (!s->dist.owned[i]) continue;
        int I = grid_lookup(&w->grid, s->grid.coord + 3 * (size_t)i);
        if (I < 0) return INFINITY;
        for (int e = 0; e < width; ++e)
            worst = fmax(worst, fabs(local[(size_t)width * i + e] - whole[(size_t)width * I + e]) / scale);
    }
    return worst;
}

static void check_scene(const CommOps *comm, const char *scene, double scale)
{
    SceneStep whole;
    int st = scene_step_open(&whole, scene, scale);
    CHECK(st == MPM_OK, "%s: the whole scene: %s", scene, mpm_last_error());
    Scene sc;
    SceneLoadOptions lo = {.scale = scale};
    Simulation sim;
    int loaded = !st && !(st = scene_load(scene, &lo, &sc));
    int started = loaded && !(st = sim_init(&sim, &sc));
    if (!st) st = sim_distribute(&sim, comm);
    if (!st) st = step_begin(&sim);
    CHECK(st == MPM_OK, "%s rank %d: the distributed step: %s", scene, comm->rank, mpm_last_error());
    if (st) goto done;
    const Simulation *w = &whole.sim;
    const int n = sim.grid.n, N = w->grid.n;
    double counts[2] = {sim.p.n, sim.dist.n_owned};
    comm->sum(comm->ctx, counts, 2);
    CHECK(counts[0] == w->p.n && counts[1] == N, "%s: %g particles and %g owned nodes, the whole scene %zu and %d",
          scene, counts[0], counts[1], w->p.n, N);
    CHECK(sim.dt == w->dt, "%s rank %d: dt %.17g, the whole scene's %.17g", scene, comm->rank, sim.dt, w->dt);
    double ghosts = sim.dist.plan.n_ghosts;
    comm->sum(comm->ctx, &ghosts, 1);
    if (comm->ranks > 1) CHECK(ghosts > 0, "%s: a halo to test", scene);

    CHECK(owned_diff(&sim, w, sim.grid.mass, w->grid.mass, 1) <= 1e-13, "%s rank %d: node masses differ", scene,
          comm->rank);
    CHECK(owned_diff(&sim, w, sim.grid.v, w->grid.v, 3) <= 1e-12, "%s rank %d: grid velocities differ by %.3g", scene,
          comm->rank, owned_diff(&sim, w, sim.grid.v, w->grid.v, 3));
    CHECK(owned_diff(&sim, w, sim.pb.kappa, w->pb.kappa, 1) <= 1e-12, "%s rank %d: CN scales differ by %.3g", scene,
          comm->rank, owned_diff(&sim, w, sim.pb.kappa, w->pb.kappa, 1));
    int bc_differ = 0;
    for (int i = 0; i < n; ++i) {
        int I = grid_lookup(&w->grid, sim.grid.coord + 3 * (size_t)i);
        bc_differ += I < 0 || sim.pb.bc[i] != w->pb.bc[I];
    }
    CHECK(bc_differ == 0, "%s rank %d: %d nodes with another constraint", scene, comm->rank, bc_differ);

    double *dv = malloc(sizeof(double) * 3 * (size_t)n), *DV = malloc(sizeof(double) * 3 * (size_t)N);
    double *g = malloc(sizeof(double) * 3 * (size_t)n), *G = malloc(sizeof(double) * 3 * (size_t)N);
    double *y = malloc(sizeof(double) * 3 * (size_t)n), *Y = malloc(sizeof(double) * 3 * (size_t)N);
    double *D = malloc(sizeof(double) * 9 * (size_t)n), *DD = malloc(sizeof(double) * 9 * (size_t)N);
    for (int I = 0; I < N; ++I)
        for (int d = 0; d < 3; ++d) DV[3 * I + d] = field(w->grid.coord + 3 * (size_t)I, d, w->grid.dx);
    for (int i = 0; i < n; ++i)
        for (int d = 0; d < 3; ++d)
            dv[3 * i + d] = sim.dist.owned[i] ? field(sim.grid.coord + 3 * (size_t)i, d, sim.grid.dx) : 1e30;
    double e = problem_energy(&sim.pb, dv), E = problem_energy(&whole.sim.pb, DV);
    CHECK(fabs(e - E) <= 1e-12 * fabs(E), "%s rank %d: energy %.17g, the whole scene's %.17g", scene, comm->rank, e, E);
    problem_gradient(&sim.pb, dv, g);
    problem_gradient(&whole.sim.pb, DV, G);
    double gd = owned_diff(&sim, w, g, G, 3);
    CHECK(gd <= 1e-12, "%s rank %d: gradients differ by %.3g", scene, comm->rank, gd);
    double r = problem_cn_residual(&sim.pb, g), R = problem_cn_residual(&whole.sim.pb, G);
    CHECK(fabs(r - R) <= 1e-12 * R, "%s rank %d: CN residual %.17g, the whole scene's %.17g", scene, comm->rank, r, R);
    double tau = problem_tau(&sim.pb, 1e-7), TAU = problem_tau(&whole.sim.pb, 1e-7);
    CHECK(fabs(tau - TAU) <= 1e-14 * TAU, "%s rank %d: tau %.17g, the whole scene's %.17g", scene, comm->rank, tau, TAU);
    CHECK(problem_tangent(&sim.pb, 1) == MPM_OK && problem_tangent(&whole.sim.pb, 1) == MPM_OK, "tangents");
    problem_hessvec(&sim.pb, dv, y);
    problem_hessvec(&whole.sim.pb, DV, Y);
    double hd = owned_diff(&sim, w, y, Y, 3);
    CHECK(hd <= 1e-12, "%s rank %d: H x differ by %.3g", scene, comm->rank, hd);
    problem_diagonal(&sim.pb, D);
    problem_diagonal(&whole.sim.pb, DD);
    double dd = owned_diff(&sim, w, D, DD, 9);
    CHECK(dd <= 1e-12, "%s rank %d: diagonals differ by %.3g", scene, comm->rank, dd);
    /* the rank's assembled part: its product and diagonal completed over
     * the ranks equal the whole scene's assembled ones */
    Bsr h = {0}, HW = {0};
    double *ya = malloc(sizeof(double) * 3 * (size_t)n), *Da = malloc(sizeof(double) * 9 * (size_t)n);
    CHECK(problem_assemble(&sim.pb, &h) == MPM_OK && problem_assemble(&whole.sim.pb, &HW) == MPM_OK,
          "%s rank %d: assembly: %s", scene, comm->rank, mpm_last_error());
    problem_assembled_product(&sim.pb, &h, dv, ya);
    problem_assembled_product(&whole.sim.pb, &HW, DV, Y);
    double ha = owned_diff(&sim, w, ya, Y, 3);
    CHECK(ha <= 1e-12, "%s rank %d: assembled H x differ by %.3g", scene, comm->rank, ha);
    problem_assembled_diagonal(&sim.pb, &h, Da);
    problem_assembled_diagonal(&whole.sim.pb, &HW, DD);
    double da = owned_diff(&sim, w, Da, DD, 9);
    CHECK(da <= 1e-12, "%s rank %d: assembled diagonals differ by %.3g", scene, comm->rank, da);
    int ghost_bad = 0;
    for (int i = 0; i < n; ++i) {
        if (sim.dist.owned[i]) continue;
        for (int d = 0; d < 3; ++d) ghost_bad += g[3 * i + d] != 0.0 || y[3 * i + d] != 0.0 || ya[3 * i + d] != 0.0;
        for (int k = 0; k < 9; ++k) ghost_bad += D[9 * i + k] != (k % 4 == 0 ? 1.0 : 0.0) || Da[9 * i + k] != D[9 * i + k];
    }
    bsr_free(&h), bsr_free(&HW), free(ya), free(Da);
    CHECK(ghost_bad == 0, "%s rank %d: %d ghost entries of outgoing fields are not zero (identity)", scene, comm->rank,
          ghost_bad);
    CHECK(!sim.pb.comm_failed, "%s rank %d: a halo exchange failed", scene, comm->rank);
    free(dv), free(DV), free(g), free(G), free(y), free(Y), free(D), free(DD);
done:
    if (started) sim_free(&sim);
    if (loaded) scene_free(&sc);
    scene_step_close(&whole);
}

int main(void)
{
    CommOps comm;
    int st = petsc_comm_open(&comm);
    CHECK(st == MPM_OK, "petsc_comm_open: %s", mpm_last_error());
    if (st) return test_summary("test_dist_problem");
    check_scene(&comm, "bar3", 4.0);
    check_scene(&comm, "wheel", 6.0);
    char name[64];
    snprintf(name, sizeof name, "test_dist_problem (rank %d of %d)", comm.rank, comm.ranks);
    comm.close(comm.ctx);
    return test_summary(name);
}
