/* Coloured symmetric block Gauss-Seidel (HOT reference §5.2, SPEC 5 and 6).
 *
 * One symmetric sweep from zero computes delta = (D+U)^-1 D (D+L)^-1 r, where
 * D, L, U are the 3x3-block diagonal, strictly-lower and strictly-upper parts
 * of A in the *processing order*: colours 0..7 (node_order.h), blocks of a
 * colour (in parallel), nodes of a block in increasing index. Two nodes in
 * different blocks of one colour are never coupled (the stencil reaches at
 * most +-4 nodes, same-colour blocks are >= 5 apart), so the parallel sweep
 * is exactly the sequential one and bitwise reproducible for any thread
 * count. For symmetric positive definite A the operator is SPD.
 *
 * The sweep needs no per-node rank: h (forward) and delta (backward) start at
 * zero, so summing A_ij x_j over the whole row only picks up the nodes that
 * were already processed. */
#ifndef MPM_SGS_H
#define MPM_SGS_H

#include "core/bsr.h"
#include "core/node_order.h"
#include "solvers/inverse_approx.h"

/* delta = (D+U)^-1 D (D+L)^-1 r. A: n x n block matrix over nodes sorted by
 * node_order_key and coloured by `col`; Dinv: 9n inverted diagonal blocks;
 * work: 6n doubles (3n for h, 3n for D h). r and delta (3n) must not
 * overlap work; r may not alias delta. Always returns MPM_OK. */
int sgs_sweep(const Bsr *A, const double *Dinv, const NodeColoring *col, const double *r, double *delta,
              double *work);

/* The same sweep with the blocks read from `val`, a single-precision copy
 * of A's values (bsr_values_single); Dinv stays double (SPEC 6.10). */
int sgs_sweep_single(const Bsr *A, const float *val, const double *Dinv, const NodeColoring *col, const double *r,
                     double *delta, double *work);

/* Checks the colouring premise: no block of A couples two nodes lying in
 * different 4x4x4 blocks of the same colour (MPM_EINTERNAL if one does).
 * O(nnz); used by tests and debug checks. */
int sgs_check_coloring(const Bsr *A, const NodeColoring *col);

/* "sgs": one symmetric sweep from zero as the preconditioner (PN-SGS-PCG,
 * HOT Table 3). Needs the assembled matrix (InvSetupInput.H). H and the
 * colouring are referenced, not copied: they must stay unchanged until the
 * next setup. */
extern const InvApproxOps inv_sgs_ops;

#endif
