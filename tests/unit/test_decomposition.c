/* floor: core */
/* The split of the grid over ranks (core/dist/decomposition.c) and the
 * counted halo volumes (core/dist/halo_census.c):
 * - the Morton key interleaves the block coordinates (known values, a
 *   2x2x2 cube in Z order, distinct keys on a cube with negative
 *   coordinates);
 * - the cut gives every rank a contiguous interval of the curve, at least
 *   one particle, and a particle count within one block's count of N/R;
 *   more ranks than particle blocks is refused;
 * - every count of the census equals a brute-force count from the stencils
 *   (touched, ghost and owned nodes, the ranks talked to, and the Hessian
 *   blocks per row from every pair of nodes one particle reaches), for 1 to
 *   7 ranks on a clustered particle cloud, and one rank has no halo. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/dist/decomposition.h"
#include "core/dist/halo_census.h"
#include "core/error.h"
#include "core/grid.h"
#include "core/particles.h"
#include "tests/common/testutil.h"

static void check_curve_keys(void)
{
    int z[3] = {0, 0, 0};
    uint64_t k0 = block_curve_key(z);
    /* the offset coordinates 2^20 have only bit 20 set: bits 62, 61, 60 of the key */
    CHECK(k0 == (1ull << 62 | 1ull << 61 | 1ull << 60), "key of the origin block: %llx", (unsigned long long)k0);
    int order[8][3] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {0, 1, 1}, {1, 0, 0}, {1, 0, 1}, {1, 1, 0}, {1, 1, 1}};
    for (int i = 0; i + 1 < 8; ++i)
        CHECK(block_curve_key(order[i]) + 1 == block_curve_key(order[i + 1]), "Z order of the unit cube at %d", i);
    int far[3] = {1, 1, 2}; /* after the whole first 2x2x2 cube */
    CHECK(block_curve_key(far) > block_curve_key(order[7]), "the next cube comes after the first");
    enum { S = 6 };
    uint64_t keys[S * S * S];
    int m = 0;
    for (int x = -3; x < 3; ++x)
        for (int y = -3; y < 3; ++y)
            for (int w = -3; w < 3; ++w) keys[m++] = block_curve_key((int[3]){x, y, w});
    int dup = 0;
    for (int i = 0; i < m; ++i)
        for (int j = i + 1; j < m; ++j) dup += keys[i] == keys[j];
    CHECK(dup == 0, "%d equal keys among %d blocks", dup, m);
}

static uint64_t rng_next(unsigned long long *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    uint64_t z = *s;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    return z ^ (z >> 31);
}

/* Two clusters of different density and a sparse haze, dx = 1: about 200
 * particle blocks with very different counts. */
/* A scene with no particle yet: every block, near and far, negative
 * coordinates included, belongs to rank 0 (its first cut comes later) */
static void check_all_on_first(void)
{
    Decomposition d;
    CHECK(decomposition_all_on_first(4, &d) == MPM_OK, "all on first: %s", mpm_last_error());
    const int blocks[4][3] = {{0, 0, 0}, {-7, 3, 100}, {1 << 19, -(1 << 19), 5}, {(1 << 20) - 1, (1 << 20) - 1, (1 << 20) - 1}};
    for (int b = 0; b < 4; ++b)
        CHECK(decomposition_owner(&d, blocks[b]) == 0, "all on first: block (%d, %d, %d) on rank %d", blocks[b][0],
              blocks[b][1], blocks[b][2], decomposition_owner(&d, blocks[b]));
    decomposition_free(&d);
    CHECK(decomposition_all_on_first(0, &d) == MPM_EINPUT, "all on first: 0 ranks accepted");
    mpm_clear_error();
}

static void make_cloud(Particles *p, size_t n)
{
    unsigned long long s = 42;
    for (size_t k = 0; k < n; ++k) {
        double x[3], v[3] = {0, 0, 0};
        int which = (int)(rng_next(&s) % 10);
        for (int d = 0; d < 3; ++d) {
            double u = (double)(rng_next(&s) >> 11) / 9007199254740992.0;
            x[d] = which < 6 ? 3 + 8 * u : which < 9 ? 14 + 12 * u : -9 + 40 * u;
        }
        particles_push(p, x, v, 1.0, 1.0, 0);
    }
}

static void check_balance(const Stencils *st, const Grid *g)
{
    size_t n = st->n;
    int max_block = 0;
    for (int q = 0; q < st->pcolor.n_blocks; ++q) {
        int c = st->pcolor.block_start[q + 1] - st->pcolor.block_start[q];
        if (c > max_block) max_block = c;
    }
    for (int R = 1; R <= 16; ++R) {
        Decomposition d;
        int status = decomposition_balance(st->base, n, R, &d);
        CHECK(status == MPM_OK, "R=%d: %s", R, mpm_last_error());
        if (status) continue;
        size_t count[16] = {0};
        int bad_order = 0;
        for (size_t k = 0; k < n; ++k) {
            int r = decomposition_node_owner(&d, st->base + 3 * k);
            ++count[r];
            int B[3];
            node_block_of(st->base + 3 * k, B);
            uint64_t key = block_curve_key(B);
            bad_order += key < d.first_key[r] || key >= d.first_key[r + 1];
        }
        CHECK(bad_order == 0, "R=%d: %d particles outside their rank's interval", R, bad_order);
        for (int r = 0; r < R; ++r) {
            CHECK(count[r] > 0, "R=%d: rank %d owns no particle", R, r);
            double off = (double)count[r] - (double)n / R;
            CHECK(off <= max_block && -off <= max_block, "R=%d rank %d: %zu particles, %g from N/R (largest block %d)",
                  R, r, count[r], off, max_block);
        }
        for (int r = 0; r < R; ++r) CHECK(d.first_key[r] < d.first_key[r + 1], "R=%d: interval %d empty", R, r);
        decomposition_free(&d);
    }
    Decomposition d;
    int too_many = st->pcolor.n_blocks + 1;
    int status = decomposition_balance(st->base, n, too_many, &d);
    CHECK(status == MPM_EINPUT && strstr(mpm_last_error(), "more ranks than blocks"), "%d ranks: %s", too_many,
          mpm_last_error());
    mpm_clear_error();
    CHECK(decomposition_balance(st->base, n, 0, &d) == MPM_EINPUT, "0 ranks refused");
    mpm_clear_error();
    (void)g;
}

/* Every count of the census against one made from scratch: every pair
 * (node of a particle's stencil, node of the same stencil) of every
 * particle, no shortcut. */
static void check_census(const Stencils *st, const Grid *g)
{
    const int n = g->n;
    unsigned char *pair = malloc((size_t)n * (size_t)n);
    unsigned char *touch = malloc((size_t)n);
    for (int R = 1; R <= 7; ++R) {
        Decomposition d;
        if (decomposition_balance(st->base, st->n, R, &d)) {
            CHECK(0, "R=%d: %s", R, mpm_last_error());
            continue;
        }
        RankCensus census[7];
        CHECK(halo_census(&d, g, st, census) == MPM_OK, "R=%d census: %s", R, mpm_last_error());
        unsigned char sends[7][7] = {{0}};
        int owned[7] = {0}, untouched[7] = {0};
        unsigned char *touched_by_owner = calloc((size_t)n, 1);
        for (int r = 0; r < R; ++r) {
            memset(pair, 0, (size_t)n * (size_t)n);
            memset(touch, 0, (size_t)n);
            size_t particles = 0;
            for (size_t k = 0; k < st->n; ++k) {
                if (decomposition_node_owner(&d, st->base + 3 * k) != r) continue;
                ++particles;
                const int *node = st->node + 27 * k;
                for (int s = 0; s < 27; ++s) {
                    if (node[s] < 0) continue;
                    touch[node[s]] = 1;
                    for (int t = 0; t < 27; ++t)
                        if (node[t] >= 0) pair[(size_t)node[s] * n + node[t]] = 1;
                }
            }
            int touched = 0, ghosts = 0;
            long ghost_rows = 0, own_rows = 0;
            for (int i = 0; i < n; ++i) {
                if (!touch[i]) continue;
                ++touched;
                int o = decomposition_node_owner(&d, g->coord + 3 * (size_t)i);
                long row = 0;
                for (int j = 0; j < n; ++j) row += pair[(size_t)i * n + j];
                if (o == r) {
                    own_rows += row;
                    touched_by_owner[i] = 1;
                } else {
                    ++ghosts;
                    ghost_rows += row;
                    sends[r][o] = 1;
                }
            }
            const RankCensus *c = census + r;
            CHECK(c->particles == particles, "R=%d rank %d: particles %zu, brute force %zu", R, r, c->particles,
                  particles);
            CHECK(c->touched_nodes == touched, "R=%d rank %d: touched %d, brute force %d", R, r, c->touched_nodes,
                  touched);
            CHECK(c->ghost_nodes == ghosts, "R=%d rank %d: ghosts %d, brute force %d", R, r, c->ghost_nodes, ghosts);
            CHECK(c->ghost_row_blocks == ghost_rows, "R=%d rank %d: ghost row blocks %ld, brute force %ld", R, r,
                  c->ghost_row_blocks, ghost_rows);
            CHECK(c->owned_row_blocks == own_rows, "R=%d rank %d: owned row blocks %ld, brute force %ld", R, r,
                  c->owned_row_blocks, own_rows);
        }
        for (int i = 0; i < n; ++i) {
            int o = decomposition_node_owner(&d, g->coord + 3 * (size_t)i);
            ++owned[o];
            untouched[o] += !touched_by_owner[i];
        }
        int total_owned = 0;
        for (int r = 0; r < R; ++r) {
            int to = 0, from = 0;
            for (int o = 0; o < R; ++o) to += sends[r][o], from += sends[o][r];
            CHECK(census[r].owned_nodes == owned[r], "R=%d rank %d: owned %d, brute force %d", R, r,
                  census[r].owned_nodes, owned[r]);
            CHECK(census[r].owned_untouched == untouched[r], "R=%d rank %d: owned untouched %d, brute force %d", R, r,
                  census[r].owned_untouched, untouched[r]);
            CHECK(census[r].send_ranks == to && census[r].receive_ranks == from,
                  "R=%d rank %d: sends to %d and receives from %d, brute force %d and %d", R, r, census[r].send_ranks,
                  census[r].receive_ranks, to, from);
            total_owned += census[r].owned_nodes;
        }
        CHECK(total_owned == n, "R=%d: %d nodes owned of %d", R, total_owned, n);
        if (R == 1)
            CHECK(census[0].ghost_nodes == 0 && census[0].owned_untouched == 0 && census[0].send_ranks == 0 &&
                      census[0].touched_nodes == n,
                  "one rank: %d ghosts, %d untouched", census[0].ghost_nodes, census[0].owned_untouched);
        if (R == 4) /* the case has a halo to count */
            CHECK(census[0].ghost_nodes > 0 && census[1].send_ranks > 0, "R=4: no halo (%d ghosts)",
                  census[0].ghost_nodes);
        free(touched_by_owner);
        decomposition_free(&d);
    }
    free(pair);
    free(touch);
}

int main(void)
{
    check_curve_keys();
    check_all_on_first();
    Particles p = {0};
    Grid g = {0};
    Stencils st = {0};
    make_cloud(&p, 3000);
    int status = grid_build(&g, &st, &p, 1.0);
    CHECK(status == MPM_OK, "grid_build: %s", mpm_last_error());
    if (!status) {
        CHECK(st.pcolor.n_blocks > 20, "the cloud has %d particle blocks", st.pcolor.n_blocks);
        check_balance(&st, &g);
        check_census(&st, &g);
    }
    grid_free(&g);
    stencils_free(&st);
    particles_free(&p);
    return test_summary("test_decomposition");
}
