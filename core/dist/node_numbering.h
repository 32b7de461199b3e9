/* One global number per node of a scene split over ranks, for a library
 * that stores the whole scene's matrix in parts (PETSc's parallel
 * matrices): rank r's owned nodes take the numbers first_r .. first_r +
 * n_owned_r - 1 in their local order, first_r the owned nodes of the ranks
 * before r; a ghost takes its owner's number. */
#ifndef MPM_NODE_NUMBERING_H
#define MPM_NODE_NUMBERING_H

#include "core/dist/comm_ops.h"

typedef struct {
    int n_owned; /* this rank's owned nodes */
    int first;   /* the number of its first owned node */
    int total;   /* every rank's owned nodes */
} NodeNumbering;

/* global[0..n) for the n local nodes (owned[i] = 1 where this rank owns
 * node i; the halo plan of comm is this grid's). Collective: every rank
 * calls it, and fails when any rank fails. */
int dist_node_numbering(const CommOps *comm, const unsigned char *owned, int n, int *global, NodeNumbering *out);

#endif
