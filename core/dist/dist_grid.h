/* A rank's grid in a distributed run (docs/distributed.md): the nodes its
 * particles reach, plus the nodes it owns that only other ranks' particles
 * reach, and the halo plan that ties each ghost (a local node another rank
 * owns) to its owner's copy.
 *
 * Built collectively (every rank calls it together; comm_ops.h): each rank
 * sends the coordinates of its ghosts to their owners, an owner adds the
 * nodes it did not have and answers with its local ids, and the plan goes
 * to the communication table (halo_plan). With one rank and comm_serial()
 * it is grid_build with an empty halo. */
#ifndef MPM_DIST_GRID_H
#define MPM_DIST_GRID_H

#include "core/dist/comm_ops.h"
#include "core/dist/decomposition.h"
#include "core/grid.h"

typedef struct {
    int n_owned;           /* local nodes this rank owns */
    unsigned char *owned;  /* per local node: 1 when this rank owns it */
    HaloPlan plan;         /* the ghosts: local id, owner rank, the owner's local id */
    int *ghost_node, *owner_rank, *owner_node; /* the plan's storage */
    int n_extra;           /* owned nodes only other ranks' particles reach */
    size_t migrated;       /* particles this rank has sent to others since the start (dist_migrate) */
    int cap_nodes, cap_ghosts;
} DistGrid;

/* Builds g and st from this rank's particles p (those whose base node's
 * block d gives to comm->rank) and fills dg. Collective. When any rank
 * fails, every rank returns a failure: its own message, or "another rank
 * failed" on the others. */
int dist_grid_build(DistGrid *dg, const Decomposition *d, const CommOps *comm, Grid *g, Stencils *st, Particles *p,
                    double dx);

void dist_grid_free(DistGrid *dg);

#endif
