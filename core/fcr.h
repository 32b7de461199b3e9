/* Fixed-corotated elasticity (Stomakhin et al. 2012; SPEC 3, HOT reference §2).
 *
 *   psi = mu |F - R|_F^2 + lambda/2 (J - 1)^2
 *   P   = 2 mu (F - R) + lambda (J - 1) cof(F)
 *
 * dP/dF is a 9x9 row-major matrix over row-major vectorised 3x3 matrices:
 *   A[9*(3*a + b) + (3*c + d)] = dP_ab / dF_cd.
 * The projected variant clamps, in singular-value space, the 3x3 block
 * d2psi/dsigma2 and the three 2x2 twist/flip blocks at eigenvalue 0 and
 * rebuilds A (Teran et al. 2005; HOT reference §1.7), so it is symmetric
 * positive semidefinite. */
#ifndef MPM_FCR_H
#define MPM_FCR_H

/* Lame parameters from Young's modulus and Poisson ratio. */
void fcr_lame(double E, double nu, double *mu, double *lambda);

/* Energy density only (line searches). */
double fcr_psi(const double F[9], double mu, double lambda);

/* Energy density and first Piola-Kirchhoff stress P (one SVD). */
double fcr_psi_P(const double F[9], double mu, double lambda, double P[9]);

/* dP/dF at F, projected to SPD when `projected` is non-zero. */
void fcr_dPdF(const double F[9], double mu, double lambda, int projected, double A[81]);

/* Replaces the symmetric 3x3 matrix A by its projection onto the PSD cone
 * (eigenvalues clamped at 0, as HOT's makePD; HOT reference §1.7): the
 * projected dP/dF's step on d2psi/dsigma2, shared with fcr_dPdF4. */
void fcr_sym3_clamp_psd(double A[3][3]);

/* ||dP/dF (F = I)||_F over the full 9x9: sqrt(3(2mu+lambda)^2 + 6 lambda^2 + 12 mu^2)
 * (SPEC 4, the characteristic-norm stiffness a_p). */
double fcr_rest_stiffness(double mu, double lambda);

#endif
