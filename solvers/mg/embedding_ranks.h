/* A node-embedding coarse level over MPI ranks (docs/distributed.md, "HOT
 * across ranks").
 *
 * Each rank embeds its owned fine nodes (mg_transfer_build); the coarse
 * nodes it reaches are the union of what every rank reaches, exactly the
 * coarse set one process finds for the whole fine level, with the same
 * weights. A coarse node at level l has integer coordinates c on the grid of
 * spacing 2^l dx, i.e. fine-grid position 2^l c, and belongs to the rank
 * that owns the fine block at that position (the decomposition's rule for
 * fine nodes, so coarse nodes stay with the fine ones around them). A rank
 * reaching a coarse node it does not own (a ghost coarse node) asks the
 * owner for the node's global number; the owner adds the node to its owned
 * set, which may hold nodes only other ranks reach. Global numbers are as
 * dist_node_numbering's: rank r's owned coarse nodes, sorted by
 * node_order_key, take first_r, first_r + 1, ... Collective. */
#ifndef MPM_MG_EMBEDDING_RANKS_H
#define MPM_MG_EMBEDDING_RANKS_H

#include "core/dist/comm_ops.h"
#include "core/dist/decomposition.h"
#include "solvers/mg/embedding.h"

typedef struct {
    int n_owned, first, total; /* this rank's coarse nodes, its first number, every rank's */
    int *owned_coord;          /* 3 n_owned, sorted by node_order_key: the next level's fine nodes */
    int *global;               /* per coarse node of the transfer (T->n_coarse): its global number */
    int cap_owned, cap_global;
} MgCoarseRanks;

/* The coarse level `level` (1 = one coarsening of the fine grid) of
 * transfer T (built from this rank's owned nodes of level - 1): its owned
 * nodes and the global numbers of T's coarse nodes. Every rank calls it;
 * a failure on any rank fails every rank. */
int mg_coarse_ranks(const CommOps *comm, const Decomposition *d, int level, const MgTransfer *T, MgCoarseRanks *out);
void mg_coarse_ranks_free(MgCoarseRanks *c);

#endif
