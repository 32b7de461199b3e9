/* HOT's node-embedding Galerkin multigrid as an inverse approximation
 * (HOT paper §4 and Algorithm 2; reference §5.1-5.4; SPEC 6).
 *
 * Setup (once per time step for HOT's L-BFGS, every Newton iteration for
 * PN-MGPCG) from the BC-projected fine matrix H and the node coordinates:
 *   level 0 = H (referenced, not copied: it must stay unchanged until the next
 *   setup, as must the coordinates and colouring); level l+1 nodes and
 *   transfers from mg/transfer.h (linear or quadratic embedding); A_{l+1} =
 *   P^T A_l P (mg/galerkin.h); per-level inverted diagonal blocks and 8-colour
 *   block colouring. Coarsening stops at `levels` levels or once a level has
 *   fewer than `min_coarse_nodes` nodes.
 * Apply = one V-cycle from zero (reference §5.4):
 *   r0 = in; bbar = R_{M-2}..R_0 in
 *   down:  `sweeps` symmetric block-GS sweeps (mg sgs_sweep), r_{l+1} = R_l r_l
 *   coarsest: block-Jacobi PCG from zero, stop when
 *             sqrt(r^T D^-1 r) < coarse_tol sqrt(bbar^T D^-1 bbar), cap 10000
 *   up:    u_l += P_l u_{l+1}, r_l -= A_l P_l u_{l+1}, `sweeps` sweeps
 *   out = u0 (not projected, as in the reference).
 * With one level this is block-Jacobi PCG on H with the same 1/2 rule
 * (LBFGS-H), using the input projection.
 *
 * Options (--solver-opt): levels (3), sweeps (1), min_coarse_nodes (300),
 * coarse_tol (0.5), coarse_max_iters (10000), coarse_exact (0; 1 sets
 * coarse_tol = 1e-12, used to test that the V-cycle is then symmetric),
 * flexible (1: outer PCG uses the flexible-CG update), and for the Galerkin
 * hierarchies embedding (linear | quadratic; the preset's kernel by default).
 * stats.inner_iters counts coarse PCG iterations since the last setup. */
#ifndef MPM_MG_MG_H
#define MPM_MG_MG_H

#include <stdint.h>
#include <stdio.h>

#include "solvers/inverse_approx.h"

#define MG_MAX_LEVELS 12

extern const InvApproxOps inv_mg_linear_ops;    /* "mg-linear": HOT, PN-MGPCG */
extern const InvApproxOps inv_mg_quadratic_ops; /* "mg-quadratic": HOT-quadratic */
/* "gmg": the baseline geometric multigrid of SPEC 6 (LBFGS-GMG, PN-GMG-PCG):
 * the same V-cycle, but every coarse level is rediscretised from the
 * particles at spacing 2^l dx (mg/gmg_level.h) instead of R A P; needs
 * InvSetupInput.problem with a current tangent. */
extern const InvApproxOps inv_gmg_ops;

typedef struct {
    int n_levels;
    int embedding; /* MgEmbedding */
    int rediscretized; /* baseline GMG */
    int n[MG_MAX_LEVELS];              /* nodes per level */
    int64_t nnzb[MG_MAX_LEVELS];       /* stored blocks per level */
    double avg_row[MG_MAX_LEVELS];     /* nonzero blocks per row, mean */
    int max_row[MG_MAX_LEVELS];        /* and max */
    double setup_s;                    /* whole setup (last call) */
    double transfer_s, galerkin_s, diag_s; /* parts of it */
    long vcycles, coarse_iters, coarse_capped; /* since the last setup */
    double smooth_s[MG_MAX_LEVELS];    /* apply time split, since the last setup */
    double transfer_apply_s, coarse_s;
} MgInfo;

/* Non-zero when self is one of the multigrid inverse approximations. */
int mg_is_multigrid(const InvApprox *self);
/* Fills info for an InvApprox created from one of the two tables above
 * (MPM_EINTERNAL for any other). */
int mg_get_info(const InvApprox *self, MgInfo *info);
/* One line per level: nodes, blocks, blocks per row (avg/max); setup times. */
void mg_print_info(const MgInfo *info, FILE *f);

#endif
