/* floor: adapters */
/* needs: MPM_WITH_PETSC */
/* The halo of a distributed grid (core/dist/dist_grid.c) through the
 * communication table, serial (core/dist/comm_serial.c) and PETSc's
 * (adapters/petsc_comm.c). Run as is it is one rank; tests/dist/
 * test_dist_halo_mpi.sh runs it under mpirun with 2 and 3 ranks.
 *
 * A clustered cloud of particles is split by the decomposition; every rank
 * scatters its own particles' mass and momentum to its grid (owned nodes,
 * ghosts, and owned nodes only others reach), sums the halo into the
 * owners and copies it back; every rank also builds the whole grid from all
 * particles as the reference. Checked:
 * - every node of the whole grid is owned by exactly one rank;
 * - after the halo sum every owned node's mass and momentum equal the
 *   whole grid's to 1e-13 relative (the same terms in another order), and
 *   after the halo copy every ghost's too;
 * - the total mass over owned nodes equals the particles' (conservation);
 * - the reductions: a sum in rank order, the same bits on every rank; max;
 * - a failure on one rank only (a decomposition for the wrong rank count
 *   on the last rank) ends dist_grid_build on every rank with an error,
 *   "another rank failed" on the others, and no rank waits forever. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "adapters/petsc_comm.h"
#include "core/dist/comm_ops.h"
#include "core/dist/decomposition.h"
#include "core/dist/dist_grid.h"
#include "core/error.h"
#include "core/grid.h"
#include "core/particles.h"
#include "tests/common/testutil.h"

static uint64_t rng_next(unsigned long long *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    uint64_t z = *s;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    return z ^ (z >> 31);
}

static double uniform(unsigned long long *s) { return (double)(rng_next(s) >> 11) / 9007199254740992.0; }

/* Two clusters and a haze, dx = 1, masses and velocities varying. */
static void make_cloud(Particles *p, size_t n)
{
    unsigned long long s = 7;
    for (size_t k = 0; k < n; ++k) {
        double x[3], v[3];
        int which = (int)(rng_next(&s) % 10);
        for (int d = 0; d < 3; ++d) {
            double u = uniform(&s);
            x[d] = which < 6 ? 3 + 9 * u : which < 9 ? 13 + 10 * u : -6 + 34 * u;
            v[d] = uniform(&s) - 0.5;
        }
        particles_push(p, x, v, 0.5 + uniform(&s), 1.0, 0);
    }
}

/* mass (1 per node) and momentum (3 per node) of particles p on grid g */
static void scatter(const Grid *g, const Stencils *st, const Particles *p, double *mass, double *mom)
{
    memset(mass, 0, sizeof(double) * (size_t)g->n);
    memset(mom, 0, sizeof(double) * 3 * (size_t)g->n);
    for (size_t k = 0; k < p->n; ++k) {
        double w[27];
        stencil_weights(st, k, w, NULL);
        for (int s = 0; s < 27; ++s) {
            int i = st->node[27 * k + s];
            if (i < 0) continue;
            mass[i] += w[s] * p->mass[k];
            for (int d = 0; d < 3; ++d) mom[3 * (size_t)i + d] += w[s] * p->mass[k] * p->v[3 * k + d];
        }
    }
}

static double largest(const double *a, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; ++i) m = fmax(m, fabs(a[i]));
    return m;
}

static void check_reductions(const CommOps *c, const char *name)
{
    double v[2] = {c->rank + 1.0, 0.1 * (c->rank + 1)};
    CHECK(c->sum(c->ctx, v, 2) == MPM_OK, "%s sum: %s", name, mpm_last_error());
    double expect0 = c->ranks * (c->ranks + 1) / 2.0, expect1 = 0;
    for (int r = 0; r < c->ranks; ++r) expect1 += 0.1 * (r + 1); /* rank order */
    CHECK(v[0] == expect0 && v[1] == expect1, "%s sum: %.17g %.17g, expected %.17g %.17g", name, v[0], v[1], expect0,
          expect1);
    double m = c->rank;
    CHECK(c->max(c->ctx, &m, 1) == MPM_OK && m == c->ranks - 1, "%s max: %g", name, m);
    int agreed = -1;
    CHECK(c->agree(c->ctx, c->rank == c->ranks - 1 ? MPM_ENUMERIC : MPM_OK, &agreed) == MPM_OK &&
              agreed == MPM_ENUMERIC,
          "%s agree: %d", name, agreed);
}

static void check_halo(const CommOps *c, const char *name)
{
    Particles all = {0}, mine = {0};
    Grid G = {0}, g = {0};
    Stencils GS = {0}, st = {0};
    DistGrid dg = {0};
    Decomposition d = {0};
    make_cloud(&all, 5000);
    int status = grid_build(&G, &GS, &all, 1.0);
    if (!status) status = decomposition_balance(GS.base, all.n, c->ranks, &d);
    CHECK(status == MPM_OK, "%s: the whole grid: %s", name, mpm_last_error());
    if (status) return;
    for (size_t k = 0; k < all.n; ++k)
        if (decomposition_node_owner(&d, GS.base + 3 * k) == c->rank)
            particles_push(&mine, all.x + 3 * k, all.v + 3 * k, all.mass[k], all.vol[k], 0);
    status = dist_grid_build(&dg, &d, c, &g, &st, &mine, 1.0);
    CHECK(status == MPM_OK, "%s rank %d: dist_grid_build: %s", name, c->rank, mpm_last_error());
    if (status) return;
    double owned = dg.n_owned, ghosts = dg.plan.n_ghosts, extra = dg.n_extra;
    c->sum(c->ctx, &owned, 1);
    c->sum(c->ctx, &ghosts, 1);
    c->sum(c->ctx, &extra, 1);
    CHECK(owned == G.n, "%s: %g nodes owned, the whole grid has %d", name, owned, G.n);
    if (c->ranks > 1) CHECK(ghosts > 0 && extra > 0, "%s: a halo to test (%g ghosts, %g extra)", name, ghosts, extra);

    double *M = malloc(sizeof(double) * (size_t)G.n), *P = malloc(sizeof(double) * 3 * (size_t)G.n);
    double *m = malloc(sizeof(double) * (size_t)g.n), *p = malloc(sizeof(double) * 3 * (size_t)g.n);
    scatter(&G, &GS, &all, M, P);
    scatter(&g, &st, &mine, m, p);
    CHECK(c->halo_sum(c->ctx, m, 1) == MPM_OK && c->halo_sum(c->ctx, p, 3) == MPM_OK, "%s halo sum: %s", name,
          mpm_last_error());
    const double mscale = largest(M, (size_t)G.n), pscale = largest(P, 3 * (size_t)G.n);
    double worst_owned = 0, worst_ghost = 0, local_mass = 0;
    int missing = 0;
    for (int i = 0; i < g.n; ++i) {
        if (!dg.owned[i]) continue;
        int I = grid_lookup(&G, g.coord + 3 * (size_t)i);
        if (I < 0) {
            ++missing;
            continue;
        }
        local_mass += m[i];
        worst_owned = fmax(worst_owned, fabs(m[i] - M[I]) / mscale);
        for (int dd = 0; dd < 3; ++dd) worst_owned = fmax(worst_owned, fabs(p[3 * i + dd] - P[3 * (size_t)I + dd]) / pscale);
    }
    CHECK(missing == 0, "%s rank %d: %d owned nodes not in the whole grid", name, c->rank, missing);
    CHECK(worst_owned <= 1e-13, "%s rank %d: owned nodes after the halo sum differ by %.3g (relative)", name, c->rank,
          worst_owned);
    CHECK(c->halo_copy(c->ctx, m, 1) == MPM_OK && c->halo_copy(c->ctx, p, 3) == MPM_OK, "%s halo copy: %s", name,
          mpm_last_error());
    for (int i = 0; i < g.n; ++i) {
        int I = grid_lookup(&G, g.coord + 3 * (size_t)i);
        if (I < 0 || dg.owned[i]) continue;
        worst_ghost = fmax(worst_ghost, fabs(m[i] - M[I]) / mscale);
        for (int dd = 0; dd < 3; ++dd) worst_ghost = fmax(worst_ghost, fabs(p[3 * i + dd] - P[3 * (size_t)I + dd]) / pscale);
    }
    CHECK(worst_ghost <= 1e-13, "%s rank %d: ghosts after the halo copy differ by %.3g (relative)", name, c->rank,
          worst_ghost);
    double particle_mass = 0;
    for (size_t k = 0; k < all.n; ++k) particle_mass += all.mass[k];
    c->sum(c->ctx, &local_mass, 1);
    CHECK(fabs(local_mass - particle_mass) <= 1e-12 * particle_mass, "%s: grid mass %.17g, particles' %.17g", name,
          local_mass, particle_mass);

    /* a failure on the last rank only: every rank returns an error */
    if (c->ranks > 1) {
        Decomposition wrong = {0};
        int use_wrong = c->rank == c->ranks - 1;
        if (use_wrong && decomposition_balance(GS.base, all.n, c->ranks + 1, &wrong)) use_wrong = 0;
        mpm_clear_error();
        status = dist_grid_build(&dg, use_wrong ? &wrong : &d, c, &g, &st, &mine, 1.0);
        const char *msg = mpm_last_error();
        CHECK(status != MPM_OK, "%s rank %d: a failure on one rank did not fail this one", name, c->rank);
        CHECK(use_wrong ? strstr(msg, "a decomposition for") != NULL : strstr(msg, "another rank failed") != NULL,
              "%s rank %d: message '%s'", name, c->rank, msg);
        mpm_clear_error();
        decomposition_free(&wrong);
    }
    free(M), free(P), free(m), free(p);
    dist_grid_free(&dg);
    decomposition_free(&d);
    grid_free(&G), grid_free(&g);
    stencils_free(&GS), stencils_free(&st);
    particles_free(&all), particles_free(&mine);
}

int main(void)
{
    CommOps petsc;
    int st = petsc_comm_open(&petsc);
    CHECK(st == MPM_OK, "petsc_comm_open: %s", mpm_last_error());
    if (st) return test_summary("test_dist_halo");
    if (petsc.ranks == 1) {
        check_reductions(comm_serial(), "serial");
        check_halo(comm_serial(), "serial");
    }
    check_reductions(&petsc, "petsc");
    check_halo(&petsc, "petsc");
    petsc.close(petsc.ctx);
    char name[64];
    snprintf(name, sizeof name, "test_dist_halo (rank %d of %d)", petsc.rank, petsc.ranks);
    return test_summary(name);
}
