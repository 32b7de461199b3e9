/* Node-embedding transfers between multigrid levels (HOT paper §4.1, eq. 6-8;
 * reference §5.1; SPEC 6).
 *
 * A fine node with integer coordinate x embeds, per axis, into coarse nodes
 * around X = floor(x/2) (floor division, so negative coordinates work):
 *   linear:    even x -> weight 1 to X;            odd x -> 1/2, 1/2 to X, X+1
 *              (the hat function of the 2dx grid at the fine node)
 *   quadratic: even x -> 1/8, 3/4, 1/8 to X-1, X, X+1;
 *              odd x  -> 1/2, 1/2 to X, X+1
 *              (the quadratic B-spline of the 2dx grid at the fine node)
 * The 3-D weight is the product over axes; zero weights create no entry.
 * The coarse nodes are all nodes that receive a nonzero weight, sorted by
 * node_order_key (so the coarse level can be coloured like the fine one).
 * P (fine x coarse) has entries w I3 and is stored as scalar weights; R = P^T
 * is stored explicitly (rows = coarse nodes) so both transfers are gathers. */
#ifndef MPM_MG_TRANSFER_H
#define MPM_MG_TRANSFER_H

#include <stdint.h>

typedef enum { MG_EMBED_LINEAR = 0, MG_EMBED_QUADRATIC = 1 } MgEmbedding;

typedef struct {
    int n_fine, n_coarse;
    int64_t *p_ptr; /* n_fine + 1 */
    int *p_col;     /* coarse node of each entry, increasing within a row */
    double *p_w;
    int64_t *r_ptr; /* n_coarse + 1 */
    int *r_col;     /* fine node of each entry, increasing within a row */
    double *r_w;
    int *coarse_coord; /* 3 n_coarse, sorted by node_order_key */
    /* capacities (storage only grows) */
    int cap_fine, cap_coarse;
    int64_t cap_entries;
    /* coarse-node hash table (kept for reuse) */
    uint64_t *h_key;
    int *h_val;
    int64_t h_cap;
} MgTransfer;

/* Per-axis embedding: writes up to 3 coarse coordinates and weights, returns
 * how many. */
int mg_embed_1d(MgEmbedding kind, int x, int X[3], double w[3]);

/* Builds the coarse node set and P, R for fine nodes (3 n_fine coordinates,
 * sorted by node_order_key). Storage of T is reused across calls. */
int mg_transfer_build(MgTransfer *T, MgEmbedding kind, const int *fine_coord, int n_fine);
void mg_transfer_free(MgTransfer *T);

/* uf = P uc (3-vectors per node). */
void mg_prolong(const MgTransfer *T, const double *uc, double *uf);
/* rc = R rf = P^T rf. */
void mg_restrict(const MgTransfer *T, const double *rf, double *rc);

#endif
