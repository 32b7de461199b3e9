/* Plasticity return mapping, applied once per step after G2P (lagged;
 * SPEC 2 item 7, HOT reference §1.2 step 6). F is the elastic deformation
 * gradient stored on the particle; the plastic part is implicit (only its
 * volume ratio Jp is kept, for snow hardening). */
#ifndef MPM_PLASTICITY_H
#define MPM_PLASTICITY_H

#include "core/material.h"
#include "core/particles.h"

/* Von Mises on fixed corotated (HOT scenes §1.4, HOT's
 * VonMisesFixedCorotated::projectStrain): with F = U diag(s) V^T and s
 * clamped to >= 1e-4, the Kirchhoff principal stresses are
 * tau_i = 2mu(s_i-1)s_i + lambda(J-1)J. If ||dev tau|| > sqrt(2/3) tau_Y the
 * deviator is scaled onto that radius (tr tau kept) and each s_i solves
 * 2mu(s_i-1)s_i = tau_new,i - lambda(J-1)J with J the trial J (larger root);
 * F <- U diag(s_new) V^T. Afterwards ||dev tau(F)|| = sqrt(2/3) tau_Y (the
 * pressure term does not enter the deviator) and det F equals the trial J up
 * to second order in the plastic correction (this one-shot map, like HOT's,
 * does not iterate on J). Returns 1 if F was projected, 0 if the state is
 * elastic (F untouched, bitwise). Requires mu > 0. */
int plasticity_von_mises(double F[9], double mu, double lambda, double yield_stress);

/* Snow (Stomakhin et al. 2013, as in Gast et al. 2015): singular values of
 * the elastic F clamped to [1 - theta_c, 1 + theta_s] (an inverted sigma[2] is
 * clamped to 1 - theta_c too); the plastic volume ratio follows as
 * Jp <- Jp det(F_old)/det(F_new) and is then clamped to [min_Jp, max_Jp],
 * where a bound <= 0 means "no bound on that side" (HOT's Boards scene uses
 * min_Jp = -2, max_Jp = 5). Returns 1 if some singular value was clamped
 * (F and Jp updated), 0 otherwise (F and Jp untouched). */
int plasticity_snow(double F[9], double *Jp, double theta_c, double theta_s, double min_Jp, double max_Jp);

/* Snow hardening factor exp(xi (1 - Jp)) that multiplies mu and lambda
 * (Stomakhin et al. 2013, Eq. 2); 1 for xi = 0. */
double snow_hardening_factor(double Jp, double xi);

/* Applies each particle's material rule to p->F (and p->Jp for snow), in
 * parallel over particles. Von Mises uses the material's mu, lambda and
 * yield_stress (no hardening). Fails with MPM_EINTERNAL if a particle's
 * material index is out of [0, n_mats), if a snow material is present but
 * p->Jp is NULL, or if a plastic material has invalid parameters
 * (mu <= 0 or yield_stress < 0 for von Mises; theta_c outside [0, 1) or
 * theta_s < 0 for snow). Particles are left untouched on failure. */
int plasticity_apply(Particles *p, const Material *mats, int n_mats);

#endif
