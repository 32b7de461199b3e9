#include "core/dist/dist_sim.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/transfer.h"

int sim_distribute(Simulation *sim, const CommOps *comm)
{
    const Scene *sc = sim->scene;
    const char *missing = sc->transfer == TRANSFER_MLS ? "MLS transfers"
                          : sc->volumes_from_density  ? "grid-density particle volumes"
                          : sc->n_sources             ? "particle sources"
                                                      : NULL;
    if (missing) return mpm_error(MPM_EINPUT, "%s: %s are not distributed over ranks yet", sc->name, missing);
    Particles *p = &sim->p;
    size_t n = p->n;
    int *base = calloc(3 * (n ? n : 1), sizeof(int));
    size_t *perm = malloc(sizeof(size_t) * (n ? n : 1));
    double *scratch = malloc(sizeof(double) * 9 * (n ? n : 1));
    int st = base && perm && scratch ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: distributing %zu particles", n);
    for (size_t k = 0; !st && k < 3 * n; ++k) base[k] = (int)floor(p->x[k] / sc->dx - 0.5);
    /* every rank splits the same particles the same way: no communication */
    if (!st) st = decomposition_balance(base, n, comm->ranks, &sim->decomp);
    if (!st) {
        size_t kept = 0;
        for (size_t k = 0; k < n; ++k) kept += decomposition_node_owner(&sim->decomp, base + 3 * k) == comm->rank;
        size_t a = 0, b = kept; /* this rank's particles first, in their order, then the others */
        for (size_t k = 0; k < n; ++k)
            if (decomposition_node_owner(&sim->decomp, base + 3 * k) == comm->rank) perm[a++] = k;
            else perm[b++] = k;
        particles_permute(p, perm, scratch);
        p->n = kept;
    }
    free(base);
    free(perm);
    free(scratch);
    int all = MPM_OK;
    int cst = comm->agree(comm->ctx, st, &all);
    if (cst) return cst;
    if (st) return st;
    if (all) return mpm_error(all, "another rank failed (rank %d stops with it)", comm->rank);
    sim->comm = comm;
    return MPM_OK;
}

int dist_p2g_halo(Simulation *sim)
{
    const CommOps *c = sim->comm;
    Grid *g = &sim->grid;
    const unsigned char *owned = sim->dist.owned;
    double *mom = malloc(sizeof(double) * 3 * (size_t)(g->n ? g->n : 1));
    int st = mom ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: %d nodes' momentum", g->n);
    int all = MPM_OK, cst = c->agree(c->ctx, st, &all);
    if (cst || st || all) {
        free(mom);
        return cst ? cst : st ? st : mpm_error(all, "another rank failed (rank %d stops with it)", c->rank);
    }
    /* this rank's momentum (P2G left v = momentum / mass; a node only others reach has neither) */
    for (int i = 0; i < g->n; ++i)
        for (int d = 0; d < 3; ++d) mom[3 * (size_t)i + d] = g->mass[i] > 0.0 ? g->mass[i] * g->v[3 * (size_t)i + d] : 0.0;
    st = c->halo_sum(c->ctx, g->mass, 1);
    if (!st) st = c->halo_sum(c->ctx, mom, 3);
    for (int i = 0; !st && i < g->n; ++i) {
        if (!owned[i]) continue;
        for (int d = 0; d < 3; ++d)
            g->v[3 * (size_t)i + d] = g->mass[i] > 0.0 ? mom[3 * (size_t)i + d] / g->mass[i] : 0.0;
    }
    if (!st) st = c->halo_copy(c->ctx, g->v, 3);
    for (int i = 0; !st && i < g->n; ++i)
        if (!owned[i]) g->mass[i] = 0.0;
    free(mom);
    return st;
}
