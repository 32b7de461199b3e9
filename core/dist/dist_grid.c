#include "core/dist/dist_grid.h"

#include <stdlib.h>
#include <string.h>

#include "core/dist/node_pack.h"
#include "core/error.h"

static int grow(DistGrid *dg, int nodes, int ghosts)
{
    if (nodes > dg->cap_nodes) {
        unsigned char *o = realloc(dg->owned, (size_t)nodes);
        if (!o) return mpm_error(MPM_EINTERNAL, "out of memory: %d local nodes", nodes);
        dg->owned = o;
        dg->cap_nodes = nodes;
    }
    if (ghosts > dg->cap_ghosts) {
        int *a = realloc(dg->ghost_node, sizeof(int) * (size_t)ghosts);
        if (a) dg->ghost_node = a;
        int *b = a ? realloc(dg->owner_rank, sizeof(int) * (size_t)ghosts) : NULL;
        if (b) dg->owner_rank = b;
        int *c = b ? realloc(dg->owner_node, sizeof(int) * (size_t)ghosts) : NULL;
        if (!c) return mpm_error(MPM_EINTERNAL, "out of memory: %d ghost nodes", ghosts);
        dg->owner_node = c;
        dg->cap_ghosts = ghosts;
    }
    return MPM_OK;
}

int dist_grid_build(DistGrid *dg, const Decomposition *d, const CommOps *comm, Grid *g, Stencils *st, Particles *p,
                    double dx)
{
    const int R = comm->ranks, me = comm->rank;
    int *send_counts = calloc((size_t)R, sizeof(int)), *recv_counts = calloc((size_t)R, sizeof(int));
    int *offset = calloc((size_t)R + 1, sizeof(int));
    uint64_t *ghost_key = NULL, *asked = NULL, *answer = NULL, *owner_ids = NULL;
    int *extra = NULL, n_ghosts = 0, n_asked = 0;
    int status = !send_counts || !recv_counts || !offset ? mpm_error(MPM_EINTERNAL, "out of memory: halo set-up") : MPM_OK;
    if (!status && d->ranks != R)
        status = mpm_error(MPM_EINPUT, "rank %d: a decomposition for %d ranks in a run on %d", me, d->ranks, R);
    if (!status) status = grid_build(g, st, p, dx);

    /* the ghosts' coordinates, grouped by owner (in local id order within an owner) */
    if (!status) {
        for (int i = 0; i < g->n; ++i) {
            int o = decomposition_node_owner(d, g->coord + 3 * (size_t)i);
            if (o != me) ++send_counts[o], ++n_ghosts;
        }
        for (int r = 0; r < R; ++r) offset[r + 1] = offset[r] + send_counts[r];
        ghost_key = malloc(sizeof(uint64_t) * (size_t)(n_ghosts ? n_ghosts : 1));
        if (!ghost_key) status = mpm_error(MPM_EINTERNAL, "out of memory: %d ghost nodes", n_ghosts);
        for (int i = 0; !status && i < g->n; ++i) { /* offset[o]: the next free place of owner o */
            int o = decomposition_node_owner(d, g->coord + 3 * (size_t)i);
            if (o != me) ghost_key[offset[o]++] = node_pack(g->coord + 3 * (size_t)i);
        }
    }
    if ((status = comm_agree(comm, status))) goto done;
    if ((status = comm->exchange(comm->ctx, send_counts, ghost_key, recv_counts, &asked))) goto done;

    /* the nodes others asked for that this rank owns and has not got */
    for (int r = 0; r < R; ++r) n_asked += recv_counts[r];
    extra = malloc(sizeof(int) * 3 * (size_t)(n_asked ? n_asked : 1));
    answer = malloc(sizeof(uint64_t) * (size_t)(n_asked ? n_asked : 1));
    if (!extra || !answer) status = mpm_error(MPM_EINTERNAL, "out of memory: %d asked nodes", n_asked);
    int n_extra = 0;
    for (int j = 0; !status && j < n_asked; ++j) {
        int c[3];
        node_unpack(asked[j], c);
        if (decomposition_node_owner(d, c) != me)
            status = mpm_error(MPM_EINTERNAL, "rank %d asked for node (%d, %d, %d), which it does not own", me, c[0],
                               c[1], c[2]);
        else if (grid_lookup(g, c) < 0) {
            int dup = 0; /* two ranks may ask for the same node */
            for (int e = 0; e < n_extra && !dup; ++e) dup = !memcmp(extra + 3 * e, c, sizeof c);
            if (!dup) memcpy(extra + 3 * n_extra++, c, sizeof c);
        }
    }
    if (!status && n_extra) status = grid_build_with_nodes(g, st, p, dx, extra, n_extra);
    for (int j = 0; !status && j < n_asked; ++j) {
        int c[3];
        node_unpack(asked[j], c);
        answer[j] = (uint64_t)grid_lookup(g, c);
    }
    if ((status = comm_agree(comm, status))) goto done;
    /* the answers go back in the order asked: recv_counts items to each rank */
    int *back_counts = send_counts; /* what each owner answers this rank: as many as it asked */
    if ((status = comm->exchange(comm->ctx, recv_counts, answer, back_counts, &owner_ids))) goto done;

    /* the plan, with this rank's local ids after any rebuild */
    status = grow(dg, g->n, n_ghosts);
    for (int r = 0, j = 0; !status && r < R; ++r)
        for (int k = 0; k < back_counts[r]; ++k, ++j) {
            int c[3];
            node_unpack(ghost_key[j], c);
            dg->ghost_node[j] = grid_lookup(g, c);
            dg->owner_rank[j] = r;
            dg->owner_node[j] = (int)owner_ids[j];
        }
    if (!status) {
        dg->n_owned = 0;
        for (int i = 0; i < g->n; ++i) {
            dg->owned[i] = decomposition_node_owner(d, g->coord + 3 * (size_t)i) == me;
            dg->n_owned += dg->owned[i];
        }
        dg->n_extra = n_extra;
        dg->plan = (HaloPlan){n_ghosts, dg->ghost_node, dg->owner_rank, dg->owner_node};
    }
    if ((status = comm_agree(comm, status))) goto done;
    status = comm_agree(comm, comm->halo_plan(comm->ctx, &dg->plan, g->n));
done:
    free(send_counts);
    free(recv_counts);
    free(offset);
    free(ghost_key);
    free(asked);
    free(answer);
    free(owner_ids);
    free(extra);
    return status;
}

void dist_grid_free(DistGrid *dg)
{
    free(dg->owned);
    free(dg->ghost_node);
    free(dg->owner_rank);
    free(dg->owner_node);
    memset(dg, 0, sizeof *dg);
}
