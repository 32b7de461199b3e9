/* floor: driver */
/* needs: MPM_WITH_PETSC */
/* HOT's coarse levels across ranks (solvers/mg/embedding_ranks.h): the
 * first step's grid of a scene split over the ranks, each rank embedding
 * its owned nodes, against the whole scene's levels on one process.
 *
 * Checked at each of three coarse levels, on bar3 and twist: the ranks'
 * coarse nodes together are the whole scene's coarse set, each owned by
 * exactly one rank (numbers 0 .. total-1, each once, by the rank that the
 * decomposition gives the node's fine-grid position); a ghost coarse
 * node's number is its owner's for the same coordinates; and each rank's
 * owned list is sorted by node_order_key (the next level's fine nodes, as
 * the coarse sets are on one process). Serially and, from
 * tests/dist/test_dist_mpi.sh, on 2 and 3 ranks. */
#include <stdlib.h>
#include <string.h>

#include "adapters/petsc_comm.h"
#include "core/dist/dist_sim.h"
#include "core/error.h"
#include "core/node_order.h"
#include "core/scene/scene_load.h"
#include "core/step.h"
#include "solvers/mg/embedding_ranks.h"
#include "tests/common/scene_fixture.h"
#include "tests/common/testutil.h"

enum { LEVELS = 3 };

static int find_coord(const int *coord, int n, const int c[3])
{
    const uint64_t key = node_order_key(c);
    int lo = 0, hi = n - 1;
    while (lo <= hi) {
        const int mid = lo + (hi - lo) / 2;
        const uint64_t k = node_order_key(coord + 3 * (size_t)mid);
        if (k == key) return mid;
        if (k < key) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

static void check_levels(const CommOps *comm, const char *scene, double scale)
{
    SceneStep whole;
    Scene sc;
    Simulation sim;
    SceneLoadOptions lo = {.scale = scale};
    MgTransfer T[LEVELS], W[LEVELS];
    MgCoarseRanks C[LEVELS];
    memset(T, 0, sizeof T), memset(W, 0, sizeof W), memset(C, 0, sizeof C);
    int st = scene_step_open(&whole, scene, scale);
    int loaded = !st && !(st = scene_load(scene, &lo, &sc));
    int started = loaded && !(st = sim_init(&sim, &sc));
    if (!st) st = sim_distribute(&sim, comm);
    if (!st) st = step_begin(&sim);
    CHECK(st == MPM_OK, "%s rank %d: set-up: %s", scene, comm->rank, mpm_last_error());
    if (st) goto done;
    /* level 0: the owned nodes (sorted as the local grid is) and the whole grid */
    const int n = sim.grid.n;
    int *fine = malloc(sizeof(int) * 3 * (size_t)(n + 1)), n_fine = 0;
    for (int i = 0; i < n; ++i)
        if (sim.dist.owned[i]) memcpy(fine + 3 * (size_t)n_fine++, sim.grid.coord + 3 * (size_t)i, 3 * sizeof(int));
    const int *wf = whole.sim.grid.coord, *f = fine;
    int wn = whole.sim.grid.n;
    for (int l = 0; l < LEVELS && !st; ++l) {
        st = mg_transfer_build(&W[l], MG_EMBED_LINEAR, wf, wn);
        if (!st) st = mg_transfer_build(&T[l], MG_EMBED_LINEAR, f, n_fine);
        if (!st) st = mg_coarse_ranks(comm, &sim.decomp, l + 1, &T[l], &C[l]);
        CHECK(st == MPM_OK, "%s level %d rank %d: %s", scene, l + 1, comm->rank, mpm_last_error());
        if (st) break;
        const int total = C[l].total, wm = W[l].n_coarse;
        CHECK(total == wm, "%s level %d: %d coarse nodes over the ranks, the whole scene %d", scene, l + 1, total, wm);
        /* every number's coordinates and owner count, gathered from the owners */
        double *at = calloc(4 * (size_t)(total + 1), sizeof(double));
        int sorted = 1, own_rule = 1;
        for (int q = 0; q < C[l].n_owned; ++q) {
            const int *c = C[l].owned_coord + 3 * (size_t)q;
            double *a = at + 4 * (size_t)(C[l].first + q);
            a[0] = c[0], a[1] = c[1], a[2] = c[2], a[3] = 1;
            if (q && node_order_key(c) <= node_order_key(c - 3)) sorted = 0;
            const int pos[3] = {c[0] << (l + 1), c[1] << (l + 1), c[2] << (l + 1)};
            if (decomposition_node_owner(&sim.decomp, pos) != comm->rank) own_rule = 0;
        }
        CHECK(sorted, "%s level %d rank %d: owned coarse nodes not sorted by key", scene, l + 1, comm->rank);
        CHECK(own_rule, "%s level %d rank %d: owns a coarse node the decomposition gives another rank", scene, l + 1,
              comm->rank);
        CHECK(comm->sum(comm->ctx, at, 4 * total) == MPM_OK, "gathering level %d", l + 1);
        int once = 1, in_whole = 1, ghosts_right = 1;
        for (int g = 0; g < total; ++g) {
            const double *a = at + 4 * (size_t)g;
            const int c[3] = {(int)a[0], (int)a[1], (int)a[2]};
            if (a[3] != 1) once = 0;
            if (find_coord(W[l].coarse_coord, wm, c) < 0) in_whole = 0;
        }
        for (int k = 0; k < T[l].n_coarse; ++k) {
            const double *a = at + 4 * (size_t)C[l].global[k];
            const int *c = T[l].coarse_coord + 3 * (size_t)k;
            if (a[0] != c[0] || a[1] != c[1] || a[2] != c[2]) ghosts_right = 0;
        }
        CHECK(once, "%s level %d: a number owned by no rank or by two", scene, l + 1);
        CHECK(in_whole, "%s level %d: a coarse node the whole scene lacks", scene, l + 1);
        CHECK(ghosts_right, "%s level %d rank %d: a coarse node's number names other coordinates", scene, l + 1,
              comm->rank);
        if (!comm->rank)
            printf("%s level %d: %d coarse nodes over %d ranks (this rank owns %d, reaches %d)\n", scene, l + 1,
                   total, comm->ranks, C[l].n_owned, T[l].n_coarse);
        free(at);
        wf = W[l].coarse_coord, wn = wm;
        f = C[l].owned_coord, n_fine = C[l].n_owned;
    }
    free(fine);
done:
    mpm_clear_error();
    for (int l = 0; l < LEVELS; ++l) mg_transfer_free(&T[l]), mg_transfer_free(&W[l]), mg_coarse_ranks_free(&C[l]);
    if (started) sim_free(&sim);
    if (loaded) scene_free(&sc);
    scene_step_close(&whole);
}

int main(void)
{
    CommOps comm;
    int st = petsc_comm_open(&comm);
    CHECK(st == MPM_OK, "petsc_comm_open: %s", mpm_last_error());
    if (st) return test_summary("test_dist_hierarchy");
    check_levels(&comm, "bar3", 4.0);
    check_levels(&comm, "twist", 4.0);
    char name[64];
    snprintf(name, sizeof name, "test_dist_hierarchy (rank %d of %d)", comm.rank, comm.ranks);
    comm.close(comm.ctx);
    return test_summary(name);
}
