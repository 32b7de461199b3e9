/* Backward-Euler particle positions over ranks (core/dist/dist_sim.h,
 * dist_backward_euler; Gast et al. 2015 section 6.3, core/position_update.h).
 *
 * A Newton iterate x^{n+1} of a particle may leave its stencil at x^n, and
 * the velocity field there is renormalised over the nodes that exist
 * (position_update.h). One process has every node; a rank has only the
 * nodes its own particles reach. So before the update each rank asks, for
 * every node within one node of its grid that it lacks, the node's owner
 * whether the node exists and its v^{n+1} (an owner holds every node of its
 * blocks that any rank's particles reach: dist_grid.h), and runs the update
 * on its grid grown by the nodes that do. A particle moves less than a cell
 * per step (the CFL rule), so its new stencil lies within that ring; only
 * Newton iterates that wander further can see fewer nodes than on one
 * process. */
#include <stdlib.h>
#include <string.h>

#include "core/dist/dist_sim.h"
#include "core/dist/node_pack.h"
#include "core/error.h"
#include "core/position_update.h"

typedef struct {
    uint64_t key;
    double v[3];
} RemoteNode; /* a node another rank owns, with its v^{n+1} */

static int by_key(const void *a, const void *b)
{
    const uint64_t x = ((const RemoteNode *)a)->key, y = ((const RemoteNode *)b)->key;
    return (x > y) - (x < y);
}

static int by_value(const void *a, const void *b)
{
    const uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* The nodes one node around g that g lacks and another rank owns (a node of
 * this rank's own blocks that g lacks exists nowhere), sorted, each once. */
static int ring_nodes(const Grid *g, const Decomposition *d, int me, uint64_t **out, int *n_out)
{
    int n = 0, cap = 1024;
    uint64_t *key = malloc(sizeof(uint64_t) * (size_t)cap);
    if (!key) return mpm_error(MPM_EINTERNAL, "out of memory: backward-Euler ring");
    for (int i = 0; i < g->n; ++i) {
        const int *c = g->coord + 3 * (size_t)i;
        for (int o = 0; o < 27; ++o) {
            const int q[3] = {c[0] + o / 9 - 1, c[1] + (o / 3) % 3 - 1, c[2] + o % 3 - 1};
            if (grid_lookup(g, q) >= 0 || decomposition_node_owner(d, q) == me) continue;
            if (n == cap) {
                uint64_t *k = realloc(key, sizeof(uint64_t) * 2 * (size_t)cap);
                if (!k) {
                    free(key);
                    return mpm_error(MPM_EINTERNAL, "out of memory: backward-Euler ring (%d nodes)", n);
                }
                key = k;
                cap *= 2;
            }
            key[n++] = node_pack(q);
        }
    }
    qsort(key, (size_t)n, sizeof *key, by_value);
    int m = 0;
    for (int j = 0; j < n; ++j)
        if (m == 0 || key[j] != key[m - 1]) key[m++] = key[j];
    *out = key;
    *n_out = m;
    return MPM_OK;
}

int dist_backward_euler(Simulation *sim)
{
    const CommOps *c = sim->comm;
    const int R = c->ranks, me = c->rank;
    const Grid *g = &sim->grid;
    uint64_t *ring = NULL, *ask = NULL, *asked = NULL, *answer = NULL, *got = NULL;
    int n_ring = 0, n_asked = 0, n_found = 0;
    int *send_counts = calloc((size_t)R, sizeof(int)), *recv_counts = calloc((size_t)R, sizeof(int));
    int *back_counts = calloc((size_t)R, sizeof(int)), *at = calloc((size_t)R + 1, sizeof(int));
    int *found = NULL;
    RemoteNode *remote = NULL;
    double *v = NULL;
    Grid ext;
    Stencils est;
    memset(&ext, 0, sizeof ext);
    memset(&est, 0, sizeof est);
    int st = send_counts && recv_counts && back_counts && at ? MPM_OK
                                                              : mpm_error(MPM_EINTERNAL, "out of memory: %d ranks", R);
    if (!st) st = ring_nodes(g, &sim->decomp, me, &ring, &n_ring);
    /* grouped by owner (ring is sorted, so each owner's part stays sorted) */
    if (!st && !(ask = malloc(sizeof(uint64_t) * (size_t)(n_ring ? n_ring : 1))))
        st = mpm_error(MPM_EINTERNAL, "out of memory: %d ring nodes", n_ring);
    for (int j = 0; !st && j < n_ring; ++j) {
        int q[3];
        node_unpack(ring[j], q);
        send_counts[decomposition_node_owner(&sim->decomp, q)]++;
    }
    for (int r = 0; !st && r < R; ++r) at[r + 1] = at[r] + send_counts[r];
    for (int j = 0; !st && j < n_ring; ++j) {
        int q[3];
        node_unpack(ring[j], q);
        ask[at[decomposition_node_owner(&sim->decomp, q)]++] = ring[j];
    }
    if ((st = comm_agree(c, st))) goto done;
    if ((st = comm_agree(c, c->exchange(c->ctx, send_counts, ask, recv_counts, &asked)))) goto done;
    /* the answers: 4 items a node, whether it exists here and its v^{n+1} */
    for (int r = 0; r < R; ++r) n_asked += recv_counts[r];
    if (!(answer = malloc(sizeof(uint64_t) * 4 * (size_t)(n_asked ? n_asked : 1))))
        st = mpm_error(MPM_EINTERNAL, "out of memory: %d asked nodes", n_asked);
    for (int j = 0; !st && j < n_asked; ++j) {
        int q[3];
        node_unpack(asked[j], q);
        const int id = grid_lookup(g, q);
        const double zero[3] = {0, 0, 0};
        answer[4 * j] = id >= 0;
        memcpy(answer + 4 * j + 1, id >= 0 ? sim->vnew + 3 * (size_t)id : zero, 3 * sizeof(double));
    }
    for (int r = 0; r < R; ++r) recv_counts[r] *= 4;
    if ((st = comm_agree(c, st))) goto done;
    if ((st = comm_agree(c, c->exchange(c->ctx, recv_counts, answer, back_counts, &got)))) goto done;
    /* answers come back rank after rank, in the order asked: ask's order */
    found = malloc(sizeof(int) * 3 * (size_t)(n_ring ? n_ring : 1));
    remote = malloc(sizeof(RemoteNode) * (size_t)(n_ring ? n_ring : 1));
    if (!found || !remote) st = mpm_error(MPM_EINTERNAL, "out of memory: %d ring nodes", n_ring);
    for (int j = 0; !st && j < n_ring; ++j)
        if (got[4 * j]) {
            node_unpack(ask[j], found + 3 * (size_t)n_found);
            remote[n_found].key = ask[j];
            memcpy(remote[n_found++].v, got + 4 * j + 1, 3 * sizeof(double));
        }
    if (!st) qsort(remote, (size_t)n_found, sizeof *remote, by_key);
    /* the grown grid (its own stencils: building it may reorder the particles) and its v^{n+1} */
    if (!st) st = grid_build_with_nodes(&ext, &est, &sim->p, g->dx, found, n_found);
    if (!st && !(v = malloc(sizeof(double) * 3 * (size_t)(ext.n ? ext.n : 1))))
        st = mpm_error(MPM_EINTERNAL, "out of memory: %d nodes", ext.n);
    for (int i = 0; !st && i < ext.n; ++i) {
        const int *q = ext.coord + 3 * (size_t)i;
        const int id = grid_lookup(g, q);
        const RemoteNode probe = {node_pack(q), {0, 0, 0}};
        const RemoteNode *hit = id >= 0 ? NULL : bsearch(&probe, remote, (size_t)n_found, sizeof *remote, by_key);
        if (id >= 0) memcpy(v + 3 * (size_t)i, sim->vnew + 3 * (size_t)id, 3 * sizeof(double));
        else if (hit) memcpy(v + 3 * (size_t)i, hit->v, 3 * sizeof(double));
        else st = mpm_error(MPM_EINTERNAL, "backward Euler: node (%d, %d, %d) has no velocity", q[0], q[1], q[2]);
    }
    if (!st) position_update_backward_euler(&ext, &est, &sim->p, v, sim->dt, &sim->pos_stats);
    st = comm_agree(c, st);
done:
    grid_free(&ext);
    stencils_free(&est);
    free(ring), free(ask), free(asked), free(answer), free(got);
    free(send_counts), free(recv_counts), free(back_counts), free(at);
    free(found), free(remote), free(v);
    return st;
}
