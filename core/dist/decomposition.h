/* The split of one scene's grid over MPI ranks (docs/distributed.md).
 *
 * The unit of ownership is the grid's 4x4x4 node block (core/node_order.h).
 * Blocks are ordered along a Morton (Z-order) curve of their block
 * coordinates, and the curve is cut into `ranks` contiguous key intervals:
 * rank r owns every block whose key lies in [first_key[r], first_key[r+1]),
 * the first interval open below, the last open above, so every block of
 * any later step has an owner without a new cut. A particle lives on the
 * rank that owns the block of its base node; a node belongs to the owner
 * of its block.
 *
 * The cut balances particles (the work of every scatter and of the
 * Hessian's assembly is per particle): the interval ends are placed between
 * particle blocks so that the particles before each end are as close as
 * block granularity allows to r N / ranks. A Morton-contiguous range of
 * blocks is a compact region (its surface, hence its halo, grows about as
 * its volume to the 2/3), which is what keeps ghost nodes few. */
#ifndef MPM_DECOMPOSITION_H
#define MPM_DECOMPOSITION_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    int ranks;
    uint64_t *first_key; /* ranks + 1: rank r owns curve keys [first_key[r], first_key[r+1]); the
                            last entry is UINT64_MAX and first_key[0] is 0 */
} Decomposition;

/* The Morton key of the node block at block coordinates B: the bits of the
 * three coordinates (offset to be non-negative, 21 bits each) interleaved,
 * x highest. Neighbouring blocks mostly have nearby keys. */
uint64_t block_curve_key(const int B[3]);

/* The block coordinates of node coordinates c (floor(c / 4) per axis). */
static inline void node_block_of(const int c[3], int B[3])
{
    for (int d = 0; d < 3; ++d) B[d] = c[d] >= 0 ? c[d] >> 2 : -((-c[d] + 3) >> 2);
}

/* Cuts the curve into `ranks` intervals balanced by particle count, from
 * the particles' base nodes (3 ints each, as core/grid.h's Stencils.base).
 * MPM_EINPUT when ranks < 1 or when there are fewer blocks holding a
 * particle than ranks (a rank would own no particle: "more ranks than
 * blocks"); MPM_EINTERNAL when out of memory. */
int decomposition_balance(const int *base, size_t n, int ranks, Decomposition *d);

/* The two halves of decomposition_balance, for a re-cut over ranks whose
 * particles no rank holds all of (dist_rebalance). The blocks holding the
 * particles with base nodes `base`, in curve order, and their particle
 * counts (malloc'd: the caller frees both). */
int decomposition_particle_blocks(const int *base, size_t n, uint64_t **block_key, size_t **block_count, size_t *nb);
/* The cut of blocks in increasing key order (each key once) with their
 * particle counts; the errors of decomposition_balance. */
int decomposition_cut(const uint64_t *block_key, const size_t *block_count, size_t nb, int ranks, Decomposition *d);

/* Every block to rank 0 (the others own empty intervals): the split of a
 * scene that has no particle yet (filled by sources); its first real cut
 * comes from dist_rebalance once there are particles. */
int decomposition_all_on_first(int ranks, Decomposition *d);

/* The rank owning the block at block coordinates B. */
int decomposition_owner(const Decomposition *d, const int B[3]);

/* The rank owning the node at node coordinates c. */
int decomposition_node_owner(const Decomposition *d, const int c[3]);

void decomposition_free(Decomposition *d);

#endif
