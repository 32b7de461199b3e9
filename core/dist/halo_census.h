/* What each rank of a decomposition would hold and exchange in one step,
 * counted (not timed) on one process from the whole grid: the volumes the
 * distributed run's halos carry and the input of the scaling model
 * (docs/distributed.md).
 *
 * Rank r's particles are those whose base node's block it owns; the nodes
 * their stencils reach are the nodes r touches. A touched node r does not
 * own is a ghost of r: every scatter (P2G, the gradient, H x) adds into it
 * and sends the sum to its owner (a halo sum), and every node field the
 * particles read back (the grid velocity, the iterate, the search
 * direction) comes from the owner (a halo copy), so both move one value per
 * ghost node and component. Assembly adds 3x3 blocks to ghost rows, whose
 * count is exact here: the pairs (ghost node i, node j) that share a
 * stencil of one of r's particles. */
#ifndef MPM_HALO_CENSUS_H
#define MPM_HALO_CENSUS_H

#include <stddef.h>

#include "core/dist/decomposition.h"
#include "core/grid.h"

typedef struct {
    size_t particles;       /* particles r owns */
    int owned_nodes;        /* active nodes in r's blocks */
    int touched_nodes;      /* nodes r's particles reach (its local grid) */
    int ghost_nodes;        /* touched nodes owned by another rank */
    int owned_untouched;    /* owned nodes only other ranks' particles reach */
    int send_ranks;         /* ranks owning r's ghosts (r sends halo sums to them) */
    int receive_ranks;      /* ranks holding ghosts of r's nodes */
    long ghost_row_blocks;  /* 3x3 Hessian blocks r assembles into ghost rows */
    long owned_row_blocks;  /* 3x3 Hessian blocks r assembles into its own rows */
} RankCensus;

/* Counts every rank's row of `census` (d->ranks rows) from the grid and
 * stencils of all particles (grid_build on the whole scene). MPM_OK or
 * MPM_EINTERNAL (out of memory). */
int halo_census(const Decomposition *d, const Grid *g, const Stencils *st, RankCensus *census);

#endif
