/* CHOLMOD sparse Cholesky factorisation as an inverse approximation (the
 * exact-Newton reference PN-CHOLMOD, and LBFGS-H-direct of SPEC 7 after Li et
 * al. 2019: factor the start-of-step Hessian once, then every application is
 * one forward/backward triangular solve pair).
 *
 * inv_cholmod_ops ("cholmod"):
 *  - setup: copies the BC-projected block Hessian H (must be assembled and
 *    symmetric positive definite) into a scalar CHOLMOD matrix holding one
 *    triangle, runs the symbolic analysis (fill-reducing ordering, supernodal
 *    structure) only when H's sparsity pattern or size changed since the last
 *    analysis, and refactorises numerically every time. A matrix that is not
 *    positive definite fails with MPM_ENUMERIC (a numerical breakdown of the
 *    step) naming the column; the next setup then starts from a fresh
 *    analysis.
 *  - apply: z = H^-1 r exactly (up to round-off).
 * No options. View: factor nonzeros and analyses. CHOLMOD runs with its default (supernodal, AMD/METIS ordering
 * chosen by fill) settings; its own printing is off, failures come back
 * through mpm_error(). */
#ifndef MPM_CHOLMOD_DIRECT_H
#define MPM_CHOLMOD_DIRECT_H

#include "solvers/inverse_approx.h"

extern const InvApproxOps inv_cholmod_ops;

/* Nonzeros of the current factor L (CHOLMOD's count for the chosen ordering,
 * excluding supernodal padding; 0 before the first analysis) and the number of
 * symbolic analyses done since creation. Either pointer may be NULL. Returns
 * MPM_EINTERNAL if `self` is not a "cholmod" inverse approximation. */
int cholmod_direct_info(const InvApprox *self, double *factor_nnz, int *analyze_count);

/* Start-up: starts and finishes one CHOLMOD common, binding the library (and
 * the BLAS under it) before a run's first step; each solver still starts its
 * own common when created. */
int cholmod_library_startup(void);
/* The linked CHOLMOD's version, e.g. "3.0.14". */
const char *cholmod_library_version(void);

#endif
