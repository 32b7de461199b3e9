#include "core/dist/halo_census.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* The bit of offset (node t - node s) in a row's 5x5x5 neighbourhood, for
 * stencil slots s and t (slot 9a + 3b + c is node base + (a, b, c)). */
static int offset_bit(int s, int t)
{
    return (t / 9 - s / 9 + 2) * 25 + ((t / 3) % 3 - (s / 3) % 3 + 2) * 5 + (t % 3 - s % 3 + 2);
}

int halo_census(const Decomposition *d, const Grid *g, const Stencils *st, RankCensus *census)
{
    const int R = d->ranks, n = g->n, nb = st->pcolor.n_blocks;
    const int *block_start = st->pcolor.block_start;
    int *node_owner = malloc(sizeof(int) * (size_t)(n ? n : 1));
    int *stamp = malloc(sizeof(int) * (size_t)(n ? n : 1));
    int *touched = malloc(sizeof(int) * (size_t)(n ? n : 1));
    unsigned char *owner_touches = calloc((size_t)(n ? n : 1), 1);
    uint64_t *row_mask = malloc(2 * sizeof(uint64_t) * (size_t)(n ? n : 1));
    int *block_owner = malloc(sizeof(int) * (size_t)(nb ? nb : 1));
    unsigned char *sends = calloc((size_t)R * (size_t)R, 1); /* sends[r R + o]: r has ghosts that o owns */
    int status = MPM_OK;
    if (!node_owner || !stamp || !touched || !owner_touches || !row_mask || !block_owner || !sends) {
        status = mpm_error(MPM_EINTERNAL, "out of memory: halo census of %d nodes", n);
        goto done;
    }
    int bit[27][27];
    for (int s = 0; s < 27; ++s)
        for (int t = 0; t < 27; ++t) bit[s][t] = offset_bit(s, t);
    memset(census, 0, sizeof(RankCensus) * (size_t)R);
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i) {
        node_owner[i] = decomposition_node_owner(d, g->coord + 3 * (size_t)i);
        stamp[i] = -1;
    }
    for (int q = 0; q < nb; ++q) block_owner[q] = decomposition_node_owner(d, st->base + 3 * (size_t)block_start[q]);

    for (int r = 0; r < R; ++r) {
        RankCensus *c = census + r;
        int nt = 0;
        for (int q = 0; q < nb; ++q) {
            if (block_owner[q] != r) continue;
            uint32_t previous_valid = 0;
            for (int k = block_start[q]; k < block_start[q + 1]; ++k) {
                ++c->particles;
                const int *node = st->node + MPM_STENCIL * (size_t)k;
                uint32_t valid = 0;
                for (int s = 0; s < MPM_STENCIL; ++s)
                    if (node[s] >= 0) valid |= 1u << s;
                /* a particle of the cell before with the same nonzero weights adds nothing new */
                if (k > block_start[q] && valid == previous_valid &&
                    !memcmp(st->base + 3 * (size_t)k, st->base + 3 * (size_t)(k - 1), 3 * sizeof(int)))
                    continue;
                previous_valid = valid;
                for (int s = 0; s < MPM_STENCIL; ++s) {
                    if (!(valid >> s & 1)) continue;
                    int i = node[s];
                    uint64_t *m = row_mask + 2 * (size_t)i;
                    if (stamp[i] != r) {
                        stamp[i] = r;
                        touched[nt++] = i;
                        m[0] = m[1] = 0;
                    }
                    for (int t = 0; t < MPM_STENCIL; ++t)
                        if (valid >> t & 1) m[bit[s][t] >> 6] |= 1ull << (bit[s][t] & 63);
                }
            }
        }
        c->touched_nodes = nt;
        for (int j = 0; j < nt; ++j) {
            int i = touched[j], o = node_owner[i];
            long row = __builtin_popcountll(row_mask[2 * (size_t)i]) + __builtin_popcountll(row_mask[2 * (size_t)i + 1]);
            if (o == r) {
                c->owned_row_blocks += row;
                owner_touches[i] = 1;
            } else {
                ++c->ghost_nodes;
                c->ghost_row_blocks += row;
                sends[(size_t)r * R + o] = 1;
            }
        }
    }
    for (int i = 0; i < n; ++i) {
        ++census[node_owner[i]].owned_nodes;
        if (!owner_touches[i]) ++census[node_owner[i]].owned_untouched;
    }
    for (int r = 0; r < R; ++r)
        for (int o = 0; o < R; ++o) {
            census[r].send_ranks += sends[(size_t)r * R + o];
            census[o].receive_ranks += sends[(size_t)r * R + o];
        }
done:
    free(node_owner);
    free(stamp);
    free(touched);
    free(owner_touches);
    free(row_mask);
    free(block_owner);
    free(sends);
    return status;
}
