#include "core/grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/block_traversal.h"
#include "core/error.h"
#include "core/kernel.h"
#include "core/radix_sort.h"

#define BKEY_BITS 21
#define BKEY_OFFSET (1 << (BKEY_BITS - 1))

static uint64_t pack_block(int bx, int by, int bz)
{
    const uint64_t m = (1u << BKEY_BITS) - 1;
    return (((uint64_t)(bx + BKEY_OFFSET) & m) << (2 * BKEY_BITS)) |
           (((uint64_t)(by + BKEY_OFFSET) & m) << BKEY_BITS) | ((uint64_t)(bz + BKEY_OFFSET) & m);
}

static void unpack_block(uint64_t key, int b[3])
{
    const uint64_t m = (1u << BKEY_BITS) - 1;
    b[0] = (int)((key >> (2 * BKEY_BITS)) & m) - BKEY_OFFSET;
    b[1] = (int)((key >> BKEY_BITS) & m) - BKEY_OFFSET;
    b[2] = (int)(key & m) - BKEY_OFFSET;
}

static inline uint32_t hash_key(uint64_t k)
{
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdull;
    k ^= k >> 33;
    return (uint32_t)k;
}

static int block_find(const Grid *g, uint64_t key)
{
    uint32_t m = (uint32_t)g->hash_cap - 1;
    for (uint32_t h = hash_key(key) & m;; h = (h + 1) & m) {
        int b = g->hash_slot[h];
        if (b < 0) return -1;
        if (g->block_key[b] == key) return b;
    }
}

static int ensure_blocks(Grid *g, int need)
{
    if (need <= g->cap_blocks) return MPM_OK;
    int cap = need + need / 2 + 64;
    uint64_t *k = realloc(g->block_key, sizeof(uint64_t) * (size_t)cap);
    if (!k) return mpm_error(MPM_EINTERNAL, "out of memory: grid blocks");
    g->block_key = k;
    uint64_t *m = realloc(g->block_mask, sizeof(uint64_t) * (size_t)cap);
    if (!m) return mpm_error(MPM_EINTERNAL, "out of memory: grid blocks");
    g->block_mask = m;
    int *f = realloc(g->block_first, sizeof(int) * (size_t)(cap + 1));
    if (!f) return mpm_error(MPM_EINTERNAL, "out of memory: grid blocks");
    g->block_first = f;
    g->cap_blocks = cap;
    return MPM_OK;
}

static int reset_hash(Grid *g, int expected_blocks)
{
    int cap = 64;
    while (cap < 2 * expected_blocks) cap *= 2;
    if (cap > g->hash_cap) {
        int *s = realloc(g->hash_slot, sizeof(int) * (size_t)cap);
        if (!s) return mpm_error(MPM_EINTERNAL, "out of memory: grid hash");
        g->hash_slot = s;
        g->hash_cap = cap;
    }
    memset(g->hash_slot, 0xff, sizeof(int) * (size_t)g->hash_cap);
    return MPM_OK;
}

/* Inserts (or finds) a block; table must have room (load <= 1/2). */
static int block_insert(Grid *g, uint64_t key)
{
    uint32_t m = (uint32_t)g->hash_cap - 1;
    for (uint32_t h = hash_key(key) & m;; h = (h + 1) & m) {
        int b = g->hash_slot[h];
        if (b < 0) {
            b = g->n_blocks++;
            g->block_key[b] = key;
            g->block_mask[b] = 0;
            g->hash_slot[h] = b;
            return b;
        }
        if (g->block_key[b] == key) return b;
    }
}

int grid_lookup(const Grid *g, const int c[3])
{
    int b = block_find(g, pack_block(floor_div_pow2(c[0], 2), floor_div_pow2(c[1], 2), floor_div_pow2(c[2], 2)));
    if (b < 0) return -1;
    int l = ((c[0] & 3) << 4) | ((c[1] & 3) << 2) | (c[2] & 3);
    uint64_t mask = g->block_mask[b];
    if (!((mask >> l) & 1u)) return -1;
    return g->block_first[b] + __builtin_popcountll(mask & ((1ull << l) - 1));
}

int grid_block(const Grid *g, const int B[3]) { return block_find(g, pack_block(B[0], B[1], B[2])); }

static int ensure_stencils(Stencils *st, size_t n)
{
    if (n <= st->cap) return MPM_OK;
    size_t cap = n + n / 4 + 256;
    void *p;
    if (!(p = realloc(st->node, sizeof(int) * MPM_STENCIL * cap))) goto oom;
    st->node = p;
    if (!(p = realloc(st->f1d, sizeof(double) * 18 * cap))) goto oom;
    st->f1d = p;
    if (!(p = realloc(st->base, sizeof(int) * 3 * cap))) goto oom;
    st->base = p;
    if (!(p = realloc(st->perm, sizeof(size_t) * cap))) goto oom;
    st->perm = p;
    if (!(p = realloc(st->scratch, sizeof(double) * 9 * cap))) goto oom;
    st->scratch = p;
    st->cap = cap;
    return MPM_OK;
oom:
    return mpm_error(MPM_EINTERNAL, "out of memory: stencils for %zu particles", n);
}

static void compute_bases(const Particles *p, int *base, double inv_dx)
{
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < p->n; ++k)
        for (int d = 0; d < 3; ++d) base[3 * k + d] = (int)floor(p->x[3 * k + d] * inv_dx - 0.5);
}

/* Keeps particles sorted by base node in node_order_key order: grouped by
 * block (for the colouring) and, inside a block, by cell, so particles that
 * share all 27 stencil nodes are contiguous (the Hessian assembly sums them
 * locally before scattering). Stable (ties keep their order), hence the same
 * order at any thread count; cheap when already sorted. A parallel radix
 * sort (core/radix_sort.c) in place of a serial qsort (issue 21). */
static int sort_particles(Particles *p, Stencils *st, double inv_dx)
{
    size_t n = p->n;
    compute_bases(p, st->base, inv_dx);
    uint64_t *key = malloc(sizeof(uint64_t) * (n ? n : 1));
    if (!key) return mpm_error(MPM_EINTERNAL, "out of memory sorting particles");
    size_t unsorted = 0;
#pragma omp parallel for schedule(static) reduction(+ : unsorted)
    for (size_t k = 0; k < n; ++k) {
        key[k] = node_order_key(st->base + 3 * k);
        if (k > 0 && key[k] < node_order_key(st->base + 3 * (k - 1))) ++unsorted;
    }
    int status = unsorted ? radix_sort_u64(n, key, st->perm) : MPM_OK;
    free(key);
    if (status || !unsorted) return status;
    particles_permute(p, st->perm, st->scratch);
    compute_bases(p, st->base, inv_dx);
    return MPM_OK;
}

static inline int same_cell(const int a[3], const int b[3]) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

int grid_build(Grid *g, Stencils *st, Particles *p, double dx) { return grid_build_with_nodes(g, st, p, dx, NULL, 0); }

int grid_build_with_nodes(Grid *g, Stencils *st, Particles *p, double dx, const int *extra, int n_extra)
{
    int status;
    size_t np = p->n;
    double inv_dx = 1.0 / dx;
    g->dx = dx;
    if ((status = ensure_stencils(st, np))) return status;
    st->n = np;
    if ((status = sort_particles(p, st, inv_dx))) return status;

    /* Particle blocks: `base` is sorted by node_order_key of the base node's
     * block, so node_coloring_build yields contiguous particle ranges. */
    int *bb = (int *)st->scratch; /* block-aligned base coords for colouring */
    for (size_t k = 0; k < 3 * np; ++k) bb[k] = st->base[k] & ~3;
    if ((status = node_coloring_build(bb, (int)np, &st->pcolor))) return status;
    int npb = st->pcolor.n_blocks;

    /* 1D weight factors (parallel, per particle); the 27 weights and their
     * gradients are their products (stencil_weights). */
    st->mls = 0;
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < np; ++k) {
        double N[3][3], dN[3][3];
        for (int d = 0; d < 3; ++d) bspline2_1d(p->x[3 * k + d], inv_dx, N[d], dN[d]);
        memcpy(st->f1d + 18 * k, N, sizeof N);
        memcpy(st->f1d + 18 * k + 9, dN, sizeof dN);
    }

    /* Blocks touched: each particle block b touches node blocks b + {0,1}^3. */
    if ((status = ensure_blocks(g, 8 * npb + 8 + n_extra))) return status;
    if ((status = reset_hash(g, 8 * npb + 8 + n_extra))) return status;
    g->n_blocks = 0;
    int *pb_blocks = malloc(sizeof(int) * 8 * (size_t)(npb > 0 ? npb : 1));
    if (!pb_blocks) return mpm_error(MPM_EINTERNAL, "out of memory: grid build");
    for (int q = 0; q < npb; ++q) {
        const int *b0 = st->base + 3 * (size_t)st->pcolor.block_start[q];
        int B[3] = {floor_div_pow2(b0[0], 2), floor_div_pow2(b0[1], 2), floor_div_pow2(b0[2], 2)};
        for (int o = 0; o < 8; ++o)
            pb_blocks[8 * q + o] = block_insert(g, pack_block(B[0] + (o >> 2), B[1] + ((o >> 1) & 1), B[2] + (o & 1)));
    }
    /* Occupancy bits, parallel over particle blocks of one colour. */
    MPM_FOR_EACH_COLORED_BLOCK(&st->pcolor, q, k0, k_end) {
        const int *b0 = st->base + 3 * (size_t)k0;
        int B[3] = {floor_div_pow2(b0[0], 2) * 4, floor_div_pow2(b0[1], 2) * 4, floor_div_pow2(b0[2], 2) * 4};
        /* Particles come sorted by cell: OR the cell's slots with a
         * weight first, then set their bits once per cell. */
        MPM_FOR_EACH_CELL(st->base, k0, k_end, k, k1) {
            const int *base = st->base + 3 * (size_t)k;
            uint32_t slots = 0;
            for (int kk = k; kk < k1; ++kk) {
                double w[MPM_STENCIL];
                stencil_weights(st, (size_t)kk, w, NULL);
                for (int s = 0; s < MPM_STENCIL; ++s) slots |= (uint32_t)(w[s] > 0.0) << s;
            }
            for (int s = 0; s < MPM_STENCIL; ++s) {
                if (!((slots >> s) & 1u)) continue;
                int r[3] = {base[0] + s / 9 - B[0], base[1] + (s / 3) % 3 - B[1], base[2] + s % 3 - B[2]};
                int o = ((r[0] >> 2) << 2) | ((r[1] >> 2) << 1) | (r[2] >> 2);
                int l = ((r[0] & 3) << 4) | ((r[1] & 3) << 2) | (r[2] & 3);
                g->block_mask[pb_blocks[8 * q + o]] |= 1ull << l;
            }
        }
    }
    free(pb_blocks);
    for (int e = 0; e < n_extra; ++e) { /* nodes no particle here reaches (a distributed run's owned nodes) */
        const int *c = extra + 3 * (size_t)e;
        int b = block_insert(g, pack_block(floor_div_pow2(c[0], 2), floor_div_pow2(c[1], 2), floor_div_pow2(c[2], 2)));
        g->block_mask[b] |= 1ull << (((c[0] & 3) << 4) | ((c[1] & 3) << 2) | (c[2] & 3));
    }

    /* Keep non-empty blocks, sorted by key; number the nodes. */
    int nb = 0;
    for (int b = 0; b < g->n_blocks; ++b)
        if (g->block_mask[b]) {
            g->block_key[nb] = g->block_key[b];
            g->block_mask[nb] = g->block_mask[b];
            ++nb;
        }
    /* sort key+mask pairs together: pack into a temporary array */
    uint64_t *pairs = malloc(sizeof(uint64_t) * 2 * (size_t)(nb > 0 ? nb : 1));
    if (!pairs) return mpm_error(MPM_EINTERNAL, "out of memory: grid build");
    for (int b = 0; b < nb; ++b) {
        pairs[2 * b] = g->block_key[b];
        pairs[2 * b + 1] = g->block_mask[b];
    }
    qsort(pairs, (size_t)nb, 2 * sizeof(uint64_t), cmp_u64);
    g->n_blocks = nb;
    int n = 0;
    for (int b = 0; b < nb; ++b) {
        g->block_key[b] = pairs[2 * b];
        g->block_mask[b] = pairs[2 * b + 1];
        g->block_first[b] = n;
        n += __builtin_popcountll(g->block_mask[b]);
    }
    g->block_first[nb] = n;
    free(pairs);
    if ((status = reset_hash(g, nb))) return status;
    {
        uint32_t m = (uint32_t)g->hash_cap - 1;
        for (int b = 0; b < nb; ++b) {
            uint32_t h = hash_key(g->block_key[b]) & m;
            while (g->hash_slot[h] >= 0) h = (h + 1) & m;
            g->hash_slot[h] = b;
        }
    }

    /* Node arrays. */
    if (n > g->cap_nodes) {
        int cap = n + n / 4 + 256;
        void *q;
        if (!(q = realloc(g->coord, sizeof(int) * 3 * (size_t)cap))) goto oom;
        g->coord = q;
        if (!(q = realloc(g->mass, sizeof(double) * (size_t)cap))) goto oom;
        g->mass = q;
        if (!(q = realloc(g->v, sizeof(double) * 3 * (size_t)cap))) goto oom;
        g->v = q;
        g->cap_nodes = cap;
    }
    g->n = n;
#pragma omp parallel for schedule(static)
    for (int b = 0; b < nb; ++b) {
        int B[3];
        unpack_block(g->block_key[b], B);
        uint64_t mask = g->block_mask[b];
        int id = g->block_first[b];
        for (int l = 0; l < 64; ++l)
            if ((mask >> l) & 1u) {
                g->coord[3 * id] = 4 * B[0] + (l >> 4);
                g->coord[3 * id + 1] = 4 * B[1] + ((l >> 2) & 3);
                g->coord[3 * id + 2] = 4 * B[2] + (l & 3);
                ++id;
            }
    }
    if ((status = node_coloring_build(g->coord, n, &g->coloring))) return status;

    /* Stencil node ids. */
    /* The 27 lookups are made once per cell (particles sorted by cell share
     * them) and masked by each particle's own weights. */
#pragma omp parallel
    {
        int cell_node[MPM_STENCIL];
        const int *cell = NULL;
#pragma omp for schedule(static)
        for (size_t k = 0; k < np; ++k) {
            const int *base = st->base + 3 * k;
            if (!cell || !same_cell(cell, base)) {
                cell = base;
                for (int s = 0; s < MPM_STENCIL; ++s) {
                    int c[3] = {base[0] + s / 9, base[1] + (s / 3) % 3, base[2] + s % 3};
                    cell_node[s] = grid_lookup(g, c);
                }
            }
            double w[MPM_STENCIL];
            stencil_weights(st, k, w, NULL);
            int *node = st->node + MPM_STENCIL * k;
            for (int s = 0; s < MPM_STENCIL; ++s) node[s] = w[s] > 0.0 ? cell_node[s] : -1;
        }
    }
    return MPM_OK;
oom:
    return mpm_error(MPM_EINTERNAL, "out of memory: %d grid nodes", n);
}

void stencils_use_mls_gradients(Stencils *st, const Particles *p, double dx)
{
    double inv_dx = 1.0 / dx;
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < st->n; ++k) {
        double N[3][3], dN[3][3], G[3][3];
        for (int d = 0; d < 3; ++d) {
            int b = bspline2_1d(p->x[3 * k + d], inv_dx, N[d], dN[d]);
            mls_factor_1d(p->x[3 * k + d], inv_dx, b, N[d], G[d]);
        }
        memcpy(st->f1d + 18 * k + 9, G, sizeof G);
    }
    st->mls = 1;
}

void grid_free(Grid *g)
{
    free(g->coord);
    free(g->mass);
    free(g->v);
    free(g->block_key);
    free(g->block_mask);
    free(g->block_first);
    free(g->hash_slot);
    node_coloring_free(&g->coloring);
    memset(g, 0, sizeof *g);
}

void stencils_free(Stencils *st)
{
    free(st->node);
    free(st->f1d);
    free(st->base);
    free(st->perm);
    free(st->scratch);
    node_coloring_free(&st->pcolor);
    memset(st, 0, sizeof *st);
}
