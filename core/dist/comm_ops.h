/* The communication a distributed step needs, as a table of operations
 * (docs/distributed.md): core/ calls these and knows no MPI. The serial
 * table (comm_serial) is one rank with no ghosts; the PETSc one
 * (adapters/petsc_comm.h) runs them across MPI ranks with PetscSF and MPI
 * collectives.
 *
 * Every operation is collective: every rank calls it, in the same order,
 * also on its error paths, so a failure on one rank cannot leave another
 * waiting. A rank that failed before a collective says so with `agree`,
 * which gives every rank the worst status of all, and all of them stop
 * together.
 *
 * The halo: a rank's local grid holds its owned nodes and its ghost nodes
 * (nodes its particles reach that another rank owns). A halo plan lists
 * each ghost with its owner rank and the node's local id on the owner.
 * halo_sum adds every ghost's values into its owner's node (the scatters'
 * partial sums); halo_copy sets every ghost to its owner's values (the
 * fields the particles read back). A node field is `width` doubles per
 * node, stored node after node. */
#ifndef MPM_COMM_OPS_H
#define MPM_COMM_OPS_H

#include <stdint.h>

typedef struct {
    int n_ghosts;
    const int *ghost_node; /* n_ghosts: the ghost's local node id */
    const int *owner_rank; /* n_ghosts: the rank owning it (never this rank) */
    const int *owner_node; /* n_ghosts: its local node id on that rank */
} HaloPlan;

/* What a rank has communicated since its table was opened (the stats op).
 * A halo sum sends the values at this rank's ghosts and receives the other
 * ranks' values for its owned nodes; a halo copy the reverse (8 bytes a
 * value, as docs/distributed.md's census counts). Times include waiting
 * for the other ranks. */
typedef struct {
    long halo_ops;       /* halo sums and copies */
    double halo_bytes_sent, halo_bytes_received;
    double halo_s;
    long collectives;    /* agree, sum, max, exchange */
    double collective_s;
} CommStats;

typedef struct {
    void *ctx;
    int rank, ranks;
    /* *agreed = the largest status any rank passed */
    int (*agree)(void *ctx, int status, int *agreed);
    /* values[0..n) summed, or maximised, over the ranks, in place; the
     * sum's order is fixed (the same result on every rank and every run) */
    int (*sum)(void *ctx, double *values, int n);
    int (*max)(void *ctx, double *values, int n);
    /* All to all of 64-bit items: send holds send_counts[r] items for rank
     * r, rank after rank; *recv (malloc'd, the caller frees it) gets
     * recv_counts[r] items from each rank r, rank after rank. */
    int (*exchange)(void *ctx, const int *send_counts, const uint64_t *send, int *recv_counts, uint64_t **recv);
    /* the plan of the next halo operations, for a local grid of n_nodes */
    int (*halo_plan)(void *ctx, const HaloPlan *plan, int n_nodes);
    int (*halo_sum)(void *ctx, double *node_values, int width);
    int (*halo_copy)(void *ctx, double *node_values, int width);
    /* the counts so far; NULL: the table counts nothing (one rank) */
    void (*stats)(void *ctx, CommStats *out);
    void (*close)(void *ctx);
} CommOps;

/* The agreement every collective phase ends with: every rank's worst
 * status. Returns this rank's own failure, or one recorded as "another rank
 * failed" when only another rank failed, or the agreement's own failure;
 * MPM_OK when every rank succeeded. Collective. */
int comm_agree(const CommOps *comm, int status);

/* One rank: reductions return their input, the halo has no ghost (a plan
 * with ghosts is MPM_EINTERNAL), exchange copies the items to itself. */
const CommOps *comm_serial(void);

#endif
