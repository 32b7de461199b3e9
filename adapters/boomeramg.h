/* hypre BoomerAMG as an inverse approximation (docs/design.md, "the one idea": the
 * algebraic baseline PN-AMG-PCG, and LBFGS-AMG of SPEC 7).
 *
 * inv_boomeramg_ops ("boomeramg"): apply = exactly one BoomerAMG V-cycle from
 * a zero initial guess, z = M r with M a fixed, symmetric positive definite
 * operator (symmetric Gauss-Seidel smoothing down and up, Galerkin coarse
 * operators with R = P^T, Gaussian elimination on the coarsest level), so it
 * can precondition CG and initialise L-BFGS.
 *
 * Setup copies the assembled BC-projected Hessian into a hypre IJ/ParCSR
 * matrix (scalar rows, node-major interleaved unknowns x0,y0,z0,x1,...) and
 * builds a new hierarchy every time (values change every Newton iteration).
 * The IJ matrix is rebuilt too: refilling an assembled one measured slower
 * (see hypre_amg.c, build_matrix). Nothing of the old setup is kept.
 * Systems AMG: 3 functions per node, nodal coarsening. View: levels and
 * operator complexity of the last hierarchy.
 *
 * Options (--solver-opt key=value):
 *   amg_strong_threshold  strength threshold, in (0, 1); default 0.5 (hypre's
 *                         recommendation for 3D problems)
 *   amg_coarsen           HMIS (default) | PMIS | falgout
 *   amg_nodal             nodal coarsening norm: 0 = unknown-based, 1 = Frobenius,
 *                         2 = sum of |a|, 3 = largest element, 4 = row-sum norm,
 *                         6 = sum of all values; default 4 (see hypre_amg.c)
 *   amg_agg_levels        levels of aggressive coarsening, >= 0; default 0
 *   amg_interp            hypre interpolation type: 6 (extended+i, default),
 *                         0 (classical), 3 (direct), 8 (standard), 14 (extended)
 *   amg_pmax              max interpolation entries per row, >= 0 (0 = no
 *                         truncation); default 4
 *   amg_relax             6 (hybrid symmetric Gauss-Seidel, default) or 8
 *                         (l1-scaled hybrid SGS); only symmetric smoothers are
 *                         accepted so the V-cycle stays symmetric
 *   amg_sweeps            smoothing sweeps down and up, >= 1; default 1
 *   amg_max_levels        most levels in the hierarchy, >= 1; default 25
 *   amg_rbm               0 (default) or 1, 2, 3: add the three rigid rotation
 *                         modes (from InvSetupInput.coord) to the interpolation,
 *                         hypre's InterpVecVariant 1 or 2 (GM) or 3 (LN)
 *
 * MPI: hypre needs MPI. Start-up (or the first setup) starts MPI through the
 * adapters' one MPI start-up (adapters/mpi_startup.h) and calls HYPRE_Init()
 * once; at exit HYPRE_Finalize runs before MPI's finaliser, so leak checkers
 * (ASan, valgrind) see a clean process. A program that uses MPI itself must
 * call MPI_Init before the first setup and finalises MPI itself.
 * Every solve is local to the calling process: hypre runs on MPI_COMM_SELF,
 * so ranks of a distributed experiment matrix never share a hypre matrix. */
#ifndef MPM_HYPRE_AMG_H
#define MPM_HYPRE_AMG_H

#include "solvers/inverse_approx.h"

extern const InvApproxOps inv_boomeramg_ops;

/* Hierarchy of the last successful setup: number of levels and operator
 * complexity (nonzeros of all level matrices / nonzeros of the fine matrix).
 * Either pointer may be NULL. MPM_EINTERNAL if `self` is not a
 * "boomeramg" inverse approximation or has not been set up. */
int boomeramg_info(const InvApprox *self, int *levels, double *op_complexity);

/* y = A x with the matrix hypre holds after the last successful setup (the
 * tests check it equals the Hessian that was passed in). */
int boomeramg_matvec(InvApprox *self, const double *x, double *y);

/* Start-up: MPI_Init (when the program has not initialised MPI) and
 * HYPRE_Init, the once-per-process work otherwise done at the first setup,
 * so that a run can do it (and time it) before its first step. Idempotent. */
int boomeramg_library_startup(void);
/* hypre's release version, e.g. "2.26.0". */
const char *boomeramg_library_version(void);

#endif
