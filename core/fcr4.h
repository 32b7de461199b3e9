/* Fixed-corotated energy density and stress of four particles at once
 * (SPEC 3; the line search's problem_energy), and their tangent dP/dF
 * (problem_tangent, core/fcr_tangent4.c). The SVD (core/svd3.c) is a
 * chain of square roots and divisions that waits on their latency, one
 * particle at a time; here each particle has a SIMD lane, so four chains
 * share the units.
 *
 * The arithmetic is fcr_psi_P's, operation for operation and in the same
 * order, without FMA: every lane gives the scalar result bit for bit. The
 * Jacobi sweeps run until every lane has converged (a converged lane's
 * rotations are masked off, and a lane that needed no rotation in a sweep
 * needs none in the next, as in the scalar loop). Lanes the scalar code
 * treats specially (max |F_ij| outside [2^-128, 2^128], zero, not finite
 * or NaN; a rank <= 1 column after the sweeps) are recomputed by
 * fcr_psi_P.
 *
 * Two variants: AVX (4 doubles a register, chosen at run time where the
 * CPU has it) and portable (fcr_psi_P four times). */
#ifndef MPM_FCR4_H
#define MPM_FCR4_H

enum { FCR4_AUTO = 0, FCR4_PORTABLE = 1 };

/* F, P: four row-major 3x3 matrices, consecutive (36 doubles each);
 * mu, lambda, psi: four each. */
void fcr_psi_P4(const double *F, const double *mu, const double *lambda, double *P, double psi[4], int kernel);

/* fcr_dPdF (core/fcr.h) of four particles: F four consecutive row-major
 * 3x3 matrices, A four consecutive 9x9 (81 doubles each). The AVX variant
 * shares the SVD lanes above and forms Ahat, the twist/flip coefficients and
 * the rank-9 sum of A in lanes, with fcr_dPdF's operations in its order
 * (bit for bit); the projection's 3x3 eigen-solve, needed only where Ahat is
 * indefinite, runs per lane in scalar code. The lanes fcr_psi_P4 recomputes
 * are recomputed by fcr_dPdF. */
void fcr_dPdF4(const double *F, const double *mu, const double *lambda, int projected, double *A, int kernel);

/* What FCR4_AUTO uses on this CPU: "avx" or "portable". */
const char *fcr4_isa(void);

#endif
