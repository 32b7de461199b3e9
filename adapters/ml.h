/* Trilinos ML smoothed aggregation as an inverse approximation (docs/design.md,
 * "the one idea": the algebraic baselines PN-ML-PCG and LBFGS-ML; SPEC 7).
 *
 * inv_ml_ops ("ml"): apply = exactly one ML V-cycle from a zero initial
 * guess, z = M r with M a fixed, symmetric positive definite operator (the
 * same symmetric smoother before and after the coarse correction, Galerkin
 * coarse operators with R = P^T, a direct coarsest solve), so it can
 * precondition CG and initialise L-BFGS.
 *
 * The fine matrix reaches ML without a copy: ML reads the BC-projected
 * Hessian's block-CSR rows through its getrow interface and applies it
 * through the project's own (OpenMP) block matvec. ML builds its coarse
 * levels itself. The set-up is the standard one for elasticity: smoothed
 * aggregation with 3 unknowns per node and the 6 rigid-body modes of the
 * active nodes' coordinates as the near-null space. Every setup builds a new
 * hierarchy. View: levels and operator complexity of the last hierarchy.
 *
 * Options (--solver-opt key=value; all validated here, because ML calls
 * exit() on some bad input):
 *   ml_smoother     chebyshev (default) | sgs (symmetric Gauss-Seidel)
 *   ml_sweeps       Chebyshev polynomial degree or SGS sweeps, in [1, 10]; default 2
 *   ml_levels       most levels in the hierarchy, in [1, 20]; default 10
 *   ml_threshold    aggregation drop threshold, in [0, 1); default 0
 *   ml_coarse_size  largest coarsest level (rows) before ML stops coarsening,
 *                   in [1, 100000]; default 512
 *   ml_damping      prolongator smoothing factor, in [0, 2]; default 1.333
 *                   (ML's 4/3; 0 = plain aggregation)
 *   ml_rbm          on (default) | off: the 6 rigid-body modes, or only the
 *                   3 translations (ML's default null space)
 *
 * Failure modes: ML does not report a failed KLU factorisation of the
 * coarsest level to the caller; Amesos writes the matrix to
 * amesos-failure.dat in the working folder instead. The coarsest Galerkin
 * matrix of an SPD Hessian is SPD, so this is seen only with a wrong matrix.
 *
 * MPI: ML is built with MPI. Start-up starts MPI through the adapters' one
 * MPI start-up (adapters/mpi_startup.h), shared with hypre and PETSc. ML runs on MPI_COMM_SELF. ML itself runs on one
 * thread; only the fine-level matrix-vector products (the project's) are
 * threaded. */
#ifndef MPM_ML_ADAPTER_H
#define MPM_ML_ADAPTER_H

#include "solvers/inverse_approx.h"

extern const InvApproxOps inv_ml_ops;

/* Hierarchy of the last successful setup: number of levels and operator
 * complexity (nonzeros of all level matrices / nonzeros of the fine
 * matrix). Either pointer may be NULL. MPM_EINTERNAL if `self` is not an
 * "ml" inverse approximation or has not been set up. */
int ml_info(const InvApprox *self, int *levels, double *op_complexity);

/* y = A x through the fine operator ML holds after the last successful setup
 * (tests: it equals the Hessian that was passed in, so getrow is right). */
int ml_matvec(InvApprox *self, const double *x, double *y);

/* y = A x with the fine matrix rebuilt from ML's getrow rows (tests: the
 * rows ML reads are the Hessian's). */
int ml_getrow_matvec(InvApprox *self, const double *x, double *y);

/* The near-null space ml_rbm=on gives ML: ns (18 n, column-major 3n x 6) =
 * translations e_x, e_y, e_z and rotations (0,-z,y), (z,0,-x), (-y,x,0)
 * of the integer node coordinates about their centroid. */
void ml_rigid_body_modes(int n, const int *coord, double *ns);

/* Start-up: MPI (adapters/mpi_startup.h). Idempotent. */
int ml_library_startup(void);
/* the Trilinos release ML comes from, e.g. "13.2" */
const char *ml_library_version(void);

#endif
