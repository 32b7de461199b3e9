/* PETSc's KSP and PC as an inverse approximation (docs/design.md, "the one
 * idea"; docs/solvers.md, "petsc options").
 *
 * inv_petsc_ops ("petsc"): setup copies the BC-projected block Hessian into a
 * PETSc MATSEQBAIJ of block size 3 and sets up a KSP whose type and PC come
 * from PETSc's own options, given as mpmbench solver options
 * (`--solver pn:petsc:pc_type=gamg,pc_gamg_threshold=0.02`). apply is
 *  - with ksp_type=preonly (the default): exactly one PCApply from a zero
 *    guess, a fixed linear map (symmetric and positive for a symmetric PC:
 *    GAMG with Chebyshev/Jacobi smoothing, hypre, ML, Jacobi, Cholesky/LU),
 *    for a PCG preconditioner or an L-BFGS initial inverse Hessian;
 *  - with any other ksp_type: a complete KSPSolve to the KSP's own
 *    tolerances (ksp_rtol, ksp_max_it, ...), a variable operator whose
 *    iterations count as inner iterations.
 *
 * Options: every given key starting with ksp_, pc_, mg_, sub_ or mat_ is a
 * PETSc option (without its leading dash), passed to PETSc under a prefix of
 * this instance's own; ksp_type (default preonly) and pc_type (default gamg)
 * are always set. When any is given, create runs the whole set-up once on a
 * small built-in elasticity-like matrix and refuses (MPM_EINPUT, one line)
 * an option PETSc did not use (as -options_left would list it) or one PETSc
 * rejects; options that print (_view, _monitor) are refused. The adapter's
 * own option: petsc_rbm = on (default): the six rigid-body modes of the
 * active nodes' coordinates are the matrix's near-null space
 * (MatNullSpaceCreateRigidBody; GAMG's aggregation uses them), off: none.
 *
 * petsc_hierarchy = linear | quadratic (default none): the PC is a PCMG on
 * HOT's node-embedding levels (adapters/petsc_hierarchy.h), with the mg
 * inverse's options under the prefix petsc_ (petsc_levels, petsc_sweeps,
 * petsc_min_coarse_nodes, petsc_coarse_tol, petsc_coarse_max_iters,
 * petsc_coarse_exact) and petsc_smoother = sgs (the coloured SGS as a
 * PCSHELL, default) | petsc (PETSc's, from mg_levels_ options); apply then
 * is the in-house V-cycle's map (variable, unprojected).
 *
 * Setup reuse: a rebuild with the same nodes and pattern refills the kept
 * Mat's values (no new structure) and sets a fresh KSP up; a refresh
 * (reuse_refresh=1) refills the values and sets the kept KSP up again on
 * them (PETSc's SAME_NONZERO_PATTERN; GAMG keeps its interpolation with
 * pc_gamg_reuse_interpolation=1); lagged keeps everything, PETSc holding
 * its own copy of the matrix.
 *
 * MPI and start-up: PETSc needs MPI. Start-up starts it through the
 * adapters' one MPI start-up (adapters/mpi_startup.h, shared with hypre and
 * ML), then calls PetscInitialize; at exit PetscFinalize runs before MPI's
 * finaliser. PETSc runs
 * on PETSC_COMM_SELF, one thread (Debian's build has no OpenMP); the copy
 * into PETSc's storage is OpenMP-parallel. */
#ifndef MPM_PETSC_ADAPTER_H
#define MPM_PETSC_ADAPTER_H

#include <stddef.h>

#include "solvers/inverse_approx.h"

extern const InvApproxOps inv_petsc_ops;

/* Levels and operator complexity of the last setup's PC when it is a
 * multigrid one (gamg, ml, mg); 1 and 1.0 otherwise. Either pointer may be
 * NULL. MPM_EINTERNAL if `self` is not a "petsc" inverse approximation or has
 * not been set up. */
int petsc_info(const InvApprox *self, int *levels, double *op_complexity);

/* y = A x with the Mat PETSc holds after the last successful setup (tests:
 * it equals the Hessian passed in). Across ranks x and y are the rank's
 * local node vectors (zeros at ghosts, as the solvers hold them) and the
 * call is collective. */
int petsc_matvec(InvApprox *self, const double *x, double *y);

/* KSPView of the last setup's solver into text (at most cap bytes with the
 * NUL; a longer view is cut). MPM_EINTERNAL without a setup. */
int petsc_view_text(const InvApprox *self, char *text, size_t cap);

/* Start-up: MPI (adapters/mpi_startup.h), then PetscInitialize. Idempotent. */
int petsc_library_startup(void);
/* PETSc's version, e.g. "3.18.5" */
const char *petsc_library_version(void);

#endif
