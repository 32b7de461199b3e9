#include "core/dist/dist_sim.h"

#include <math.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>

#include "core/error.h"
#include "core/transfer.h"

int sim_distribute(Simulation *sim, const CommOps *comm)
{
    const Scene *sc = sim->scene;
    Particles *p = &sim->p;
    size_t n = p->n;
    int *base = calloc(3 * (n ? n : 1), sizeof(int));
    size_t *perm = malloc(sizeof(size_t) * (n ? n : 1));
    double *scratch = malloc(sizeof(double) * 9 * (n ? n : 1));
    int st = base && perm && scratch ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: distributing %zu particles", n);
    for (size_t k = 0; !st && k < 3 * n; ++k) base[k] = (int)floor(p->x[k] / sc->dx - 0.5);
    /* every rank splits the same particles the same way: no communication;
     * a scene its sources fill starts on rank 0 and is cut when they emit */
    sim->uncut = n == 0 && sc->n_sources > 0;
    if (!st) st = sim->uncut ? decomposition_all_on_first(comm->ranks, &sim->decomp)
                             : decomposition_balance(base, n, comm->ranks, &sim->decomp);
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
    if ((st = comm_agree(comm, st))) return st;
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
    if ((st = comm_agree(c, st))) {
        free(mom);
        return st;
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

/* A particle as 64-bit items for the exchange: x, v, C, F, mass, volume,
 * material, identity, then Jp when the particles keep it. */
enum { ITEMS_BASE = 3 + 3 + 9 + 9 + 1 + 1 + 1 + 1 };

static void pack_particle(const Particles *p, size_t k, uint64_t *out)
{
    double d[26];
    memcpy(d, p->x + 3 * k, 3 * sizeof(double));
    memcpy(d + 3, p->v + 3 * k, 3 * sizeof(double));
    memcpy(d + 6, p->C + 9 * k, 9 * sizeof(double));
    memcpy(d + 15, p->F + 9 * k, 9 * sizeof(double));
    d[24] = p->mass[k];
    d[25] = p->vol[k];
    memcpy(out, d, sizeof d);
    out[26] = (uint64_t)(int64_t)p->mat[k];
    out[27] = p->id ? (uint64_t)p->id[k] : 0;
    if (p->Jp) memcpy(out + ITEMS_BASE, p->Jp + k, sizeof(double));
}

static void unpack_particle(const uint64_t *in, Particles *p, size_t k)
{
    double d[26];
    memcpy(d, in, sizeof d);
    memcpy(p->x + 3 * k, d, 3 * sizeof(double));
    memcpy(p->v + 3 * k, d + 3, 3 * sizeof(double));
    memcpy(p->C + 9 * k, d + 6, 9 * sizeof(double));
    memcpy(p->F + 9 * k, d + 15, 9 * sizeof(double));
    p->mass[k] = d[24];
    p->vol[k] = d[25];
    p->mat[k] = (int)(int64_t)in[26];
    if (p->id) p->id[k] = (size_t)in[27];
    if (p->Jp) memcpy(p->Jp + k, in + ITEMS_BASE, sizeof(double));
}

/* Copies particle `from` to index `to` (to <= from). */
static void move_particle(Particles *p, size_t from, size_t to)
{
    uint64_t buf[ITEMS_BASE + 1];
    pack_particle(p, from, buf);
    unpack_particle(buf, p, to);
}

int dist_migrate(Simulation *sim, size_t *sent)
{
    const CommOps *c = sim->comm;
    const int R = c->ranks, me = c->rank;
    Particles *p = &sim->p;
    const double dx = sim->scene->dx;
    const size_t n = p->n, W = ITEMS_BASE + (p->Jp ? 1 : 0);
    int *dest = malloc(sizeof(int) * (n ? n : 1));
    int *send_counts = calloc((size_t)R, sizeof(int)), *recv_counts = calloc((size_t)R, sizeof(int));
    size_t *at = calloc((size_t)R + 1, sizeof(size_t));
    uint64_t *send = NULL, *recv = NULL;
    size_t leaving = 0;
    int st = dest && send_counts && recv_counts && at ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: migration");
    for (size_t k = 0; !st && k < n; ++k) { /* the owner of the particle's base node's block, after the move */
        int base[3];
        for (int d = 0; d < 3; ++d) base[d] = (int)floor(p->x[3 * k + d] / dx - 0.5);
        dest[k] = decomposition_node_owner(&sim->decomp, base);
        if (dest[k] != me) send_counts[dest[k]] += (int)W, ++leaving;
    }
    if (!st) {
        for (int r = 0; r < R; ++r) at[r + 1] = at[r] + (size_t)send_counts[r];
        send = malloc(sizeof(uint64_t) * (at[R] ? at[R] : 1));
        if (!send) st = mpm_error(MPM_EINTERNAL, "out of memory: %zu particles leaving", leaving);
    }
    for (size_t k = 0; !st && k < n; ++k)
        if (dest[k] != me) {
            pack_particle(p, k, send + at[dest[k]]);
            at[dest[k]] += W;
        }
    st = comm_agree(c, st);
    if (!st) st = c->exchange(c->ctx, send_counts, send, recv_counts, &recv);
    if (!st) { /* the staying particles in their order, then the arrivals rank after rank */
        size_t kept = 0, arriving = 0;
        for (size_t k = 0; k < n; ++k)
            if (dest[k] == me) move_particle(p, k, kept++);
        for (int r = 0; r < R; ++r) arriving += (size_t)recv_counts[r] / W;
        st = particles_reserve(p, kept + arriving);
        for (size_t j = 0; !st && j < arriving; ++j) unpack_particle(recv + j * W, p, kept + j);
        if (!st) p->n = kept + arriving;
    }
    if (sent) *sent = leaving;
    free(dest);
    free(send_counts);
    free(recv_counts);
    free(at);
    free(send);
    free(recv);
    return st;
}

int dist_keep_emitted(Simulation *sim, size_t n_before, double total_before)
{
    Particles *p = &sim->p;
    const double dx = sim->scene->dx;
    size_t kept = n_before;
    for (size_t k = n_before; k < p->n; ++k) {
        int base[3];
        for (int d = 0; d < 3; ++d) base[d] = (int)floor(p->x[3 * k + d] / dx - 0.5);
        /* one process numbers them after the whole scene's particles, in emission order */
        if (p->id) p->id[k] = (size_t)total_before + (k - n_before);
        if (decomposition_node_owner(&sim->decomp, base) == sim->comm->rank) move_particle(p, k, kept++);
    }
    p->n = kept;
    return MPM_OK;
}

/* Every rank's particle blocks to every rank: each rank's blocks lie in its
 * own key interval, and the intervals follow the ranks, so the blocks come
 * in curve order, each once (checked). */
static int gather_blocks(const CommOps *c, const uint64_t *key, const size_t *count, size_t nb, uint64_t **all_key,
                         size_t **all_count, size_t *n_all)
{
    const int R = c->ranks;
    int *send_counts = calloc((size_t)R, sizeof(int)), *recv_counts = calloc((size_t)R, sizeof(int));
    uint64_t *send = malloc(sizeof(uint64_t) * (2 * nb * (size_t)R + 1)), *recv = NULL;
    int st = send_counts && recv_counts && send ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: %zu blocks", nb);
    for (int r = 0; !st && r < R; ++r) {
        send_counts[r] = (int)(2 * nb);
        for (size_t b = 0; b < nb; ++b) {
            send[2 * (nb * (size_t)r + b)] = key[b];
            send[2 * (nb * (size_t)r + b) + 1] = count[b];
        }
    }
    st = comm_agree(c, st);
    if (!st) st = c->exchange(c->ctx, send_counts, send, recv_counts, &recv);
    size_t m = 0;
    for (int r = 0; !st && r < R; ++r) m += (size_t)recv_counts[r] / 2;
    *all_key = st ? NULL : malloc(sizeof(uint64_t) * (m ? m : 1));
    *all_count = st ? NULL : malloc(sizeof(size_t) * (m ? m : 1));
    if (!st && (!*all_key || !*all_count)) st = mpm_error(MPM_EINTERNAL, "out of memory: %zu blocks", m);
    for (size_t b = 0; !st && b < m; ++b) {
        (*all_key)[b] = recv[2 * b];
        (*all_count)[b] = (size_t)recv[2 * b + 1];
        if (b && (*all_key)[b] <= (*all_key)[b - 1])
            st = mpm_error(MPM_EINTERNAL, "rebalance: the ranks' blocks are not in curve order at block %zu", b);
    }
    *n_all = m;
    free(send_counts);
    free(recv_counts);
    free(send);
    free(recv);
    return comm_agree(c, st);
}

int dist_rebalance(Simulation *sim)
{
    const CommOps *c = sim->comm;
    const int R = c->ranks;
    double *count = calloc((size_t)R, sizeof(double));
    int st = comm_agree(c, count ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: %d ranks", R));
    if (st) {
        free(count);
        return st;
    }
    count[c->rank] = (double)sim->p.n;
    if (c->sum(c->ctx, count, R)) st = MPM_EINTERNAL;
    double total = 0.0, most = 0.0;
    for (int r = 0; r < R; ++r) {
        total += count[r];
        if (count[r] > most) most = count[r];
    }
    free(count);
    const double imbalance = total > 0 ? most * R / total : 1.0;
    if (imbalance > sim->worst_imbalance) sim->worst_imbalance = imbalance;
    /* the same counts on every rank: all of them cut again, or none */
    const int first_cut = sim->uncut && total > 0;
    if (st || (!first_cut && (sim->rebalance_above <= 0 || imbalance <= sim->rebalance_above))) return st;
    const Particles *p = &sim->p;
    const double dx = sim->scene->dx;
    int *base = malloc(sizeof(int) * 3 * (p->n ? p->n : 1));
    uint64_t *key = NULL, *all_key = NULL;
    size_t *cnt = NULL, *all_count = NULL, nb = 0, n_all = 0;
    st = base ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: %zu particles", p->n);
    for (size_t k = 0; !st && k < 3 * p->n; ++k) base[k] = (int)floor(p->x[k] / dx - 0.5);
    if (!st) st = decomposition_particle_blocks(base, p->n, &key, &cnt, &nb);
    free(base);
    st = comm_agree(c, st);
    if (!st) st = gather_blocks(c, key, cnt, nb, &all_key, &all_count, &n_all);
    /* fewer particle blocks than ranks: the old cut stays (every rank
     * keeps a block of it) */
    Decomposition cut = {0, NULL};
    const int can_cut = n_all >= (size_t)R;
    if (!st && can_cut) st = comm_agree(c, decomposition_cut(all_key, all_count, n_all, R, &cut));
    free(key);
    free(cnt);
    free(all_key);
    free(all_count);
    /* block granularity may give the same cut again: nothing moves then */
    int same = !st && can_cut;
    for (int r = 0; same && r <= R; ++r) same = cut.first_key[r] == sim->decomp.first_key[r];
    if (st || !can_cut || same) {
        decomposition_free(&cut);
        return st;
    }
    decomposition_free(&sim->decomp);
    sim->decomp = cut;
    sim->recuts++;
    sim->uncut = 0;
    size_t sent = 0;
    st = dist_migrate(sim, &sent);
    sim->dist.migrated += sent;
    return st;
}
