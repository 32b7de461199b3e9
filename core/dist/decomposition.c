#include "core/dist/decomposition.h"

#include <stdlib.h>

#include "core/error.h"
#include "core/radix_sort.h"

#define CURVE_BITS 21
#define CURVE_OFFSET (1 << (CURVE_BITS - 1))

/* The 21 low bits of v moved to every third bit (bit i to bit 3 i). */
static uint64_t spread_bits(uint64_t v)
{
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffull;
    v = (v | v << 16) & 0x1f0000ff0000ffull;
    v = (v | v << 8) & 0x100f00f00f00f00full;
    v = (v | v << 4) & 0x10c30c30c30c30c3ull;
    v = (v | v << 2) & 0x1249249249249249ull;
    return v;
}

uint64_t block_curve_key(const int B[3])
{
    return spread_bits((uint64_t)(B[0] + CURVE_OFFSET)) << 2 | spread_bits((uint64_t)(B[1] + CURVE_OFFSET)) << 1 |
           spread_bits((uint64_t)(B[2] + CURVE_OFFSET));
}

int decomposition_particle_blocks(const int *base, size_t n, uint64_t **block_key, size_t **block_count, size_t *nb)
{
    *block_key = NULL;
    *block_count = NULL;
    *nb = 0;
    uint64_t *key = calloc(n ? n : 1, sizeof(uint64_t));
    size_t *order = malloc(sizeof(size_t) * (n ? n : 1));
    uint64_t *bk = malloc(sizeof(uint64_t) * (n ? n : 1));
    size_t *bc = malloc(sizeof(size_t) * (n ? n : 1));
    int status = key && order && bk && bc ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory: %zu particles' blocks", n);
    for (size_t k = 0; !status && k < n; ++k) {
        int B[3];
        node_block_of(base + 3 * k, B);
        key[k] = block_curve_key(B);
    }
    if (!status) status = radix_sort_u64(n, key, order);
    size_t m = 0;
    for (size_t i = 0; !status && i < n; ++i) {
        uint64_t k = key[order[i]];
        if (m && bk[m - 1] == k) {
            ++bc[m - 1];
        } else {
            bk[m] = k;
            bc[m++] = 1;
        }
    }
    free(key);
    free(order);
    if (status) {
        free(bk);
        free(bc);
        return status;
    }
    *block_key = bk;
    *block_count = bc;
    *nb = m;
    return MPM_OK;
}

int decomposition_cut(const uint64_t *block_key, const size_t *block_count, size_t nb, int ranks, Decomposition *d)
{
    d->ranks = 0;
    d->first_key = NULL;
    if (ranks < 1) return mpm_error(MPM_EINPUT, "ranks: must be >= 1, got %d", ranks);
    size_t n = 0;
    for (size_t b = 0; b < nb; ++b) n += block_count[b];
    if (n == 0) return mpm_error(MPM_EINPUT, "ranks: %d ranks but no particle to own", ranks);
    if ((size_t)ranks > nb)
        return mpm_error(MPM_EINPUT, "ranks: %d ranks but only %zu node blocks hold particles (more ranks than "
                                     "blocks: a rank would own no particle)",
                         ranks, nb);
    d->first_key = malloc(sizeof(uint64_t) * ((size_t)ranks + 1));
    if (!d->first_key) return mpm_error(MPM_EINTERNAL, "out of memory: decomposing %zu particles", n);
    /* Rank r starts at the first block whose middle lies past r n / ranks
     * particles along the curve: each end lands within half a block of its
     * target. Every rank keeps at least one block. */
    d->first_key[0] = 0;
    size_t b = 0, before = 0; /* particles in blocks [0, b) */
    for (int r = 1; r < ranks; ++r) {
        double target = (double)n * r / ranks;
        size_t highest = nb - (size_t)(ranks - r); /* leaves a block to every later rank */
        before += block_count[b++];                   /* rank r - 1 keeps block b */
        while (b < highest && before + 0.5 * block_count[b] < target) before += block_count[b++];
        d->first_key[r] = block_key[b];
    }
    d->first_key[ranks] = UINT64_MAX;
    d->ranks = ranks;
    return MPM_OK;
}

int decomposition_balance(const int *base, size_t n, int ranks, Decomposition *d)
{
    d->ranks = 0;
    d->first_key = NULL;
    if (ranks < 1) return mpm_error(MPM_EINPUT, "ranks: must be >= 1, got %d", ranks);
    uint64_t *block_key;
    size_t *block_count, nb;
    int status = decomposition_particle_blocks(base, n, &block_key, &block_count, &nb);
    if (!status) status = decomposition_cut(block_key, block_count, nb, ranks, d);
    free(block_key);
    free(block_count);
    return status;
}

int decomposition_all_on_first(int ranks, Decomposition *d)
{
    d->ranks = 0;
    d->first_key = NULL;
    if (ranks < 1) return mpm_error(MPM_EINPUT, "ranks: must be >= 1, got %d", ranks);
    d->first_key = malloc(sizeof(uint64_t) * ((size_t)ranks + 1));
    if (!d->first_key) return mpm_error(MPM_EINTERNAL, "out of memory: decomposition over %d ranks", ranks);
    d->ranks = ranks;
    d->first_key[0] = 0;
    for (int r = 1; r <= ranks; ++r) d->first_key[r] = UINT64_MAX; /* curve keys stay below 2^63 */
    return MPM_OK;
}

int decomposition_owner(const Decomposition *d, const int B[3])
{
    uint64_t k = block_curve_key(B);
    int lo = 0, hi = d->ranks - 1; /* the last r with first_key[r] <= k */
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (d->first_key[mid] <= k) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

int decomposition_node_owner(const Decomposition *d, const int c[3])
{
    int B[3];
    node_block_of(c, B);
    return decomposition_owner(d, B);
}

void decomposition_free(Decomposition *d)
{
    free(d->first_key);
    d->first_key = NULL;
    d->ranks = 0;
}
