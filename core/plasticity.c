/* Plasticity return mappings (see plasticity.h). */
#include "core/plasticity.h"

#include "core/error.h"
#include "core/mat3.h"
#include "core/svd3.h"

#include <math.h>

/* F = U diag(s) V^T */
static void rebuild(const double U[9], const double s[3], const double V[9], double F[9])
{
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            F[3 * r + c] = U[3 * r] * s[0] * V[3 * c] + U[3 * r + 1] * s[1] * V[3 * c + 1] +
                           U[3 * r + 2] * s[2] * V[3 * c + 2];
}

int plasticity_von_mises(double F[9], double mu, double lambda, double yield_stress)
{
    /* lambda only enters tau through the pressure lambda(J-1)J, which is the
     * same on every axis and cancels both in the deviator and in the solve
     * (see below), so the map does not depend on it. Kept in the interface
     * because it is part of the model's stress. */
    (void)lambda;
    double U[9], s[3], V[9];
    svd3(F, U, s, V);
    /* HOT scenes §1.4: singular values clamped to >= 1e-4 (this also lifts an
     * inverted sigma[2]; it only takes effect if the state yields). */
    for (int k = 0; k < 3; ++k) s[k] = fmax(s[k], 1e-4);
    /* Kirchhoff principal stresses tau_k = e_k + lambda(J-1)J (J = s0 s1 s2) with the
     * deviatoric-carrying part e_k = 2mu(s_k-1)s_k. The pressure term is the
     * same for all k, so it cancels in the deviator and in the solve below;
     * working with e avoids cancellation when lambda >> mu. */
    double e[3];
    for (int k = 0; k < 3; ++k) e[k] = 2.0 * mu * (s[k] - 1.0) * s[k];
    double mean = (e[0] + e[1] + e[2]) / 3.0;
    double dev[3] = {e[0] - mean, e[1] - mean, e[2] - mean};
    double dn = sqrt(dev[0] * dev[0] + dev[1] * dev[1] + dev[2] * dev[2]);
    double radius = sqrt(2.0 / 3.0) * yield_stress;
    if (!(dn > radius)) return 0;

    /* Scale the deviator onto the yield radius keeping tr(tau), then solve
     * 2mu(s-1)s = tau_new,k - lambda(J-1)J =: c_k, i.e. 2mu s^2 - 2mu s - c_k = 0,
     * larger root s = (2mu + sqrt(4mu^2 + 8mu c_k))/(4mu)
     *               = (mu + sqrt(mu^2 + 2mu c_k))/(2mu)
     *               = (mu + sqrt(mu^2 - 2mu(lambda(J-1)J - tau_new,k)))/(2mu). */
    /* With tr(tau)/3 = mean(e) + lambda(J-1)J, c_k = mean(e) + alpha dev_k. */
    double alpha = radius / dn;
    double sn[3];
    for (int k = 0; k < 3; ++k) {
        double ck = mean + alpha * dev[k];
        double disc = mu * mu + 2.0 * mu * ck;
        if (disc < 0.0) disc = 0.0; /* below 2mu(s-1)s's minimum -mu/2: take its vertex s = 1/2 */
        sn[k] = (mu + sqrt(disc)) / (2.0 * mu);
    }
    rebuild(U, sn, V, F);
    return 1;
}

int plasticity_snow(double F[9], double *Jp, double theta_c, double theta_s, double min_Jp, double max_Jp)
{
    double U[9], s[3], V[9];
    svd3(F, U, s, V);
    double lo = 1.0 - theta_c, hi = 1.0 + theta_s;
    double sn[3];
    int clamped = 0;
    for (int k = 0; k < 3; ++k) {
        sn[k] = s[k] < lo ? lo : (s[k] > hi ? hi : s[k]);
        clamped |= sn[k] != s[k];
    }
    if (!clamped) return 0;
    /* Stomakhin et al. 2013 (deformation gradient update): F = F_E F_P is
     * kept, F_E <- U Sigma_clamped V^T and F_P <- F_E,new^-1 F, hence
     * J_P <- J_P det(F_E,old)/det(F_E,new). */
    double jold = s[0] * s[1] * s[2], jnew = sn[0] * sn[1] * sn[2];
    double jp = *Jp * (jold / jnew);
    if (min_Jp > 0.0 && jp < min_Jp) jp = min_Jp;
    if (max_Jp > 0.0 && jp > max_Jp) jp = max_Jp;
    *Jp = jp;
    rebuild(U, sn, V, F);
    return 1;
}

double snow_hardening_factor(double Jp, double xi)
{
    /* Stomakhin et al. 2013, Eq. 2: mu = mu0 exp(xi (1 - J_P)), same for lambda. */
    return xi == 0.0 ? 1.0 : exp(xi * (1.0 - Jp));
}

int plasticity_apply(Particles *p, const Material *mats, int n_mats)
{
    if (!p) return mpm_error(MPM_EINTERNAL, "plasticity_apply: no particles");
    if (p->n == 0) return MPM_OK;
    if (!mats || n_mats <= 0) return mpm_error(MPM_EINTERNAL, "plasticity_apply: no materials");

    int any_plastic = 0, need_jp = 0;
    for (int m = 0; m < n_mats; ++m) {
        const Material *mt = &mats[m];
        switch (mt->plasticity) {
        case PLASTICITY_NONE: break;
        case PLASTICITY_VON_MISES:
            if (!(mt->mu > 0.0) || !(mt->yield_stress >= 0.0) || !isfinite(mt->lambda))
                return mpm_error(MPM_EINTERNAL,
                                 "plasticity_apply: material %d (%s): von Mises needs mu > 0 and "
                                 "yield_stress >= 0 (mu %g, lambda %g, yield_stress %g)",
                                 m, mt->name, mt->mu, mt->lambda, mt->yield_stress);
            any_plastic = 1;
            break;
        case PLASTICITY_SNOW:
            if (!(mt->theta_c >= 0.0 && mt->theta_c < 1.0) || !(mt->theta_s >= 0.0))
                return mpm_error(MPM_EINTERNAL,
                                 "plasticity_apply: material %d (%s): snow needs 0 <= theta_c < 1 and "
                                 "theta_s >= 0 (theta_c %g, theta_s %g)",
                                 m, mt->name, mt->theta_c, mt->theta_s);
            any_plastic = 1;
            if (mt->hardening != 0.0) need_jp = 1; /* without hardening Jp is never read */
            break;
        default:
            return mpm_error(MPM_EINTERNAL, "plasticity_apply: material %d (%s): unknown plasticity kind %d",
                             m, mt->name, (int)mt->plasticity);
        }
    }
    if (need_jp && !p->Jp)
        return mpm_error(MPM_EINTERNAL, "plasticity_apply: snow hardening needs the plastic state p->Jp "
                                        "(particles_enable_plastic_state)");

    const long long n = (long long)p->n;
    long long first_bad = n;
#pragma omp parallel for schedule(static) reduction(min : first_bad)
    for (long long i = 0; i < n; ++i)
        if ((p->mat[i] < 0 || p->mat[i] >= n_mats) && i < first_bad) first_bad = i;
    if (first_bad < n)
        return mpm_error(MPM_EINTERNAL, "plasticity_apply: particle %lld has material index %d, not in [0, %d)",
                         first_bad, p->mat[first_bad], n_mats);
    if (!any_plastic) return MPM_OK;

    double *Fall = p->F, *Jp = p->Jp;
    const int *mat = p->mat;
#pragma omp parallel for schedule(static)
    for (long long i = 0; i < n; ++i) {
        const Material *mt = &mats[mat[i]];
        double *F = Fall + 9 * i;
        if (mt->plasticity == PLASTICITY_VON_MISES)
            plasticity_von_mises(F, mt->mu, mt->lambda, mt->yield_stress);
        else if (mt->plasticity == PLASTICITY_SNOW) {
            double unused = 1.0;
            plasticity_snow(F, Jp ? &Jp[i] : &unused, mt->theta_c, mt->theta_s, mt->min_Jp, mt->max_Jp);
        }
    }
    return MPM_OK;
}
