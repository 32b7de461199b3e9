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
 * Registered as "mg" (inv_mg_ops), one implementation for the three
 * hierarchies of the study:
 *  - rediscretize=0 (default): Galerkin coarse levels R A P with the
 *    embedding=linear (default; HOT, PN-MGPCG) or quadratic (HOT-quadratic)
 *    kernel;
 *  - rediscretize=1: the baseline geometric multigrid of SPEC 6 (LBFGS-GMG,
 *    PN-GMG-PCG): every coarse level is rediscretised from the particles at
 *    spacing 2^l dx (mg/gmg_level.h) and linked by linear transfers; needs
 *    InvSetupInput.problem with a current tangent; option coarse_bc_project
 *    (1) projects restricted residuals at each coarse level's Dirichlet nodes.
 * Options: levels (3), sweeps (1), min_coarse_nodes (300), coarse_tol (0.5),
 * coarse_max_iters (10000), coarse_exact (0; 1 sets coarse_tol = 1e-12, the
 * V-cycle is then a fixed symmetric map to that accuracy), flexible (1: outer
 * PCG uses the flexible-CG update). Integer options must be integers in
 * range. stats.inner_iters counts coarse PCG iterations since the last setup;
 * the view op prints and returns the hierarchy (nodes, blocks per row per
 * level: HOT Fig. 8) and the V-cycle counts. */
#ifndef MPM_MG_MG_H
#define MPM_MG_MG_H

#include "solvers/inverse_approx.h"

#define MG_MAX_LEVELS 12

extern const InvApproxOps inv_mg_ops;

#endif
