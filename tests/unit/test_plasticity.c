/* floor: core */
/* Plasticity: von Mises return map lands on the yield surface, keeps U, V and
 * (to second order) J, leaves elastic states bitwise alone; snow clamp bounds
 * and Jp update; plasticity_apply dispatch and error handling. */
#include "core/error.h"
#include "core/fcr.h"
#include "core/mat3.h"
#include "core/material.h"
#include "core/particles.h"
#include "core/plasticity.h"
#include "core/svd3.h"
#include "tests/common/testutil.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static unsigned long long rng = 4242;

static void random_rotation(double R[9])
{
    double w[3];
    for (int k = 0; k < 3; ++k) w[k] = test_uniform(&rng, -3.2, 3.2);
    m3_rotation(w, R);
}

/* F = R1 diag(s) R2^T, returning R1, R2. */
static void compose(const double s[3], double R1[9], double R2[9], double F[9])
{
    double D[9] = {s[0], 0, 0, 0, s[1], 0, 0, 0, s[2]}, T[9];
    random_rotation(R1);
    random_rotation(R2);
    m3_mul(R1, D, T);
    m3_mul_bt(T, R2, F);
}

/* ||dev tau|| of F for FCR, and J. */
static double dev_tau_norm(const double F[9], double mu, double lambda, double *J)
{
    double U[9], s[3], V[9];
    svd3(F, U, s, V);
    double j = s[0] * s[1] * s[2], tau[3], mean = 0;
    for (int k = 0; k < 3; ++k) {
        tau[k] = 2 * mu * (s[k] - 1) * s[k] + lambda * (j - 1) * j;
        mean += tau[k] / 3;
    }
    if (J) *J = j;
    return sqrt((tau[0] - mean) * (tau[0] - mean) + (tau[1] - mean) * (tau[1] - mean) +
                (tau[2] - mean) * (tau[2] - mean));
}

/* Is R1^T F R2 diagonal (same singular vectors)? Returns the max off-diagonal
 * relative to |F|. */
static double offdiag(const double R1[9], const double R2[9], const double F[9])
{
    double T[9], D[9];
    m3_mul_at(R1, F, T);
    m3_mul(T, R2, D);
    double o = 0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            if (r != c) o = fmax(o, fabs(D[3 * r + c]));
    return o / sqrt(m3_frob2(F));
}

static void test_von_mises(void)
{
    /* Aluminium (Boxes/Donut/Wheel) and the Sauce material (HOT scenes §1.4, §3.9). */
    struct {
        double E, nu, tauY;
    } mats[2] = {{6.9e10, 0.33, 2.4e8}, {2.07e5, 0.33, 720}};
    for (int mi = 0; mi < 2; ++mi) {
        double mu, lambda, tauY = mats[mi].tauY;
        fcr_lame(mats[mi].E, mats[mi].nu, &mu, &lambda);
        double ystrain = tauY / (2 * mu); /* deviatoric strain scale at yield */
        double worst_dJ = 0;
        int n_proj = 0, n_el = 0;
        for (int n = 0; n < 2000; ++n) {
            /* Deviatoric strains from 0.01x to 20x the yield strain, plus volume change. */
            double amp = ystrain * pow(10.0, test_uniform(&rng, -2, 1.3));
            double vol = test_uniform(&rng, -0.02, 0.02);
            double s[3];
            for (int k = 0; k < 3; ++k) s[k] = (1 + vol) * (1 + amp * test_uniform(&rng, -1, 1));
            double R1[9], R2[9], F[9], F0[9];
            compose(s, R1, R2, F);
            m3_copy(F0, F);
            double J0;
            double dn0 = dev_tau_norm(F0, mu, lambda, &J0);
            int proj = plasticity_von_mises(F, mu, lambda, tauY);
            double radius = sqrt(2.0 / 3.0) * tauY;
            if (dn0 <= radius * (1 - 1e-9)) {
                CHECK(proj == 0, "elastic state projected (dev %g, radius %g)", dn0, radius);
                CHECK(memcmp(F, F0, sizeof F) == 0, "elastic state changed");
                ++n_el;
            } else if (dn0 > radius * (1 + 1e-9)) {
                CHECK(proj == 1, "yielding state not projected (dev %g, radius %g)", dn0, radius);
                ++n_proj;
                double J1;
                double dn1 = dev_tau_norm(F, mu, lambda, &J1);
                CHECK(rel_diff(dn1, radius, 0) <= 1e-8, "not on yield surface: %.12g vs %.12g", dn1, radius);
                /* Same singular vectors. */
                CHECK(offdiag(R1, R2, F) <= 1e-12, "singular vectors changed: %g", offdiag(R1, R2, F));
                /* J is the trial J up to second order in the plastic correction
                 * (one-shot map as in HOT). The correction is < amp here. */
                double dJ = fabs(J1 / J0 - 1);
                worst_dJ = fmax(worst_dJ, dJ / (amp * amp));
                CHECK(dJ <= 5.0 * amp * amp, "J changed by %g (J0 %g, strain amplitude %g)", dJ, J0, amp);
                /* Re-applying changes nothing beyond round-off. */
                double F1[9];
                m3_copy(F1, F);
                plasticity_von_mises(F1, mu, lambda, tauY);
                double d = 0;
                for (int k = 0; k < 9; ++k) d = fmax(d, fabs(F1[k] - F[k]));
                CHECK(d <= 1e-12, "second projection moved F by %g", d);
            }
        }
        CHECK(n_proj > 200 && n_el > 200, "coverage: %d projected, %d elastic", n_proj, n_el);
        printf("von Mises (E=%g): %d projected, %d elastic, max |dJ/J|/strain^2 = %.3g\n", mats[mi].E, n_proj,
               n_el, worst_dJ);
    }
    /* Pure volume change is never plastic, however large. */
    {
        double mu, lambda;
        fcr_lame(6.9e10, 0.33, &mu, &lambda);
        double F[9] = {0.8, 0, 0, 0, 0.8, 0, 0, 0, 0.8}, F0[9];
        m3_copy(F0, F);
        CHECK(plasticity_von_mises(F, mu, lambda, 2.4e8) == 0 && memcmp(F, F0, sizeof F) == 0,
              "hydrostatic compression must be elastic");
    }
    /* Identity is elastic; an inverted F that yields comes back with s >= 1e-4 > 0. */
    {
        double F[9], F0[9];
        m3_identity(F);
        m3_copy(F0, F);
        CHECK(plasticity_von_mises(F, 1.0, 1.0, 0.0) == 0 && memcmp(F, F0, sizeof F) == 0, "identity, zero yield");
        double G[9] = {1.5, 0, 0, 0, 1.0, 0, 0, 0, -0.5};
        CHECK(plasticity_von_mises(G, 1.0, 1.0, 0.1) == 1, "inverted F should yield");
        CHECK(m3_det(G) > 0, "inverted F projected to det %g", m3_det(G));
        int fin = 1;
        for (int k = 0; k < 9; ++k) fin &= isfinite(G[k]);
        CHECK(fin, "non-finite F after projection");
    }
}

static void test_snow(void)
{
    const double tc = 0.01, ts = 0.001; /* Boards sand (HOT scenes §1.4) */
    for (int n = 0; n < 2000; ++n) {
        double s[3];
        for (int k = 0; k < 3; ++k) s[k] = test_uniform(&rng, 0.95, 1.01);
        if (n % 10 == 0) s[0] = test_uniform(&rng, 0.995, 1.0005); /* some fully inside */
        if (n % 10 == 0) s[1] = test_uniform(&rng, 0.995, 1.0005);
        if (n % 10 == 0) s[2] = test_uniform(&rng, 0.995, 1.0005);
        if (n % 7 == 0) s[2] = -s[2];
        double R1[9], R2[9], F[9], F0[9];
        compose(s, R1, R2, F);
        m3_copy(F0, F);
        double Jp0 = test_uniform(&rng, 0.5, 1.5), Jp = Jp0;
        /* The clamp acts on svd3's signed singular values (an inversion sits
         * on the smallest one), not on the s used to build F. */
        double U0[9], s0[3], V0[9];
        svd3(F0, U0, s0, V0);
        int inside = 1;
        for (int k = 0; k < 3; ++k) inside &= s0[k] >= 1 - tc && s0[k] <= 1 + ts;
        int r = plasticity_snow(F, &Jp, tc, ts, -2.0, 5.0);
        if (inside) {
            CHECK(r == 0 && memcmp(F, F0, sizeof F) == 0 && Jp == Jp0, "inside: untouched");
            continue;
        }
        CHECK(r == 1, "outside: must clamp");
        double U[9], sn[3], V[9];
        svd3(F, U, sn, V);
        for (int k = 0; k < 3; ++k)
            CHECK(sn[k] >= (1 - tc) * (1 - 1e-14) && sn[k] <= (1 + ts) * (1 + 1e-14), "sigma %g out of bounds",
                  sn[k]);
        double expect_sn[3];
        for (int k = 0; k < 3; ++k) expect_sn[k] = fmin(fmax(s0[k], 1 - tc), 1 + ts);
        double Jold = s0[0] * s0[1] * s0[2], Jnew = expect_sn[0] * expect_sn[1] * expect_sn[2];
        CHECK(rel_diff(Jp, Jp0 * Jold / Jnew, 0) <= 1e-13, "Jp %.17g expected %.17g", Jp, Jp0 * Jold / Jnew);
        CHECK(rel_diff(m3_det(F), Jnew, 0) <= 1e-13, "det F_new %g expected %g", m3_det(F), Jnew);
        CHECK(offdiag(U0, V0, F) <= 1e-13, "snow changed singular vectors");
        /* det F_E * Jp (total volume) is conserved. */
        CHECK(rel_diff(m3_det(F) * Jp, Jold * Jp0, 0) <= 1e-13, "total volume not conserved");
    }
    /* Jp bounds (only when > 0). */
    {
        double s[3] = {0.5, 0.5, 0.5}, R1[9], R2[9], F[9], Jp = 1.0;
        compose(s, R1, R2, F);
        plasticity_snow(F, &Jp, 0.025, 0.0075, 0.6, 20.0);
        CHECK(Jp == 0.6, "Jp should clamp to min_Jp: %g", Jp);
        compose(s, R1, R2, F);
        Jp = 1.0;
        plasticity_snow(F, &Jp, 0.025, 0.0075, 0.0, 0.0);
        CHECK(rel_diff(Jp, 0.125 / pow(0.975, 3), 0) < 1e-13, "no Jp bounds: %g", Jp);
        double t[3] = {2, 2, 2};
        compose(t, R1, R2, F);
        Jp = 1.0;
        plasticity_snow(F, &Jp, 0.025, 0.0075, 0.6, 2.0);
        CHECK(Jp == 2.0, "Jp should clamp to max_Jp: %g", Jp);
    }
    CHECK(snow_hardening_factor(0.7, 0.0) == 1.0, "no hardening");
    CHECK(rel_diff(snow_hardening_factor(0.9, 10.0), exp(1.0), 0) < 1e-15, "hardening e^1");
    CHECK(rel_diff(snow_hardening_factor(1.1, 10.0), exp(-1.0), 0) < 1e-15, "softening e^-1");
}

static void test_apply(void)
{
    Material mats[3];
    memset(mats, 0, sizeof mats);
    mats[0].E = 1e6;
    mats[0].nu = 0.3;
    mats[0].plasticity = PLASTICITY_NONE;
    mats[1].E = 2.07e5;
    mats[1].nu = 0.33;
    mats[1].plasticity = PLASTICITY_VON_MISES;
    mats[1].yield_stress = 720;
    mats[2].E = 1e5;
    mats[2].nu = 0.3;
    mats[2].plasticity = PLASTICITY_SNOW;
    mats[2].theta_c = 0.01;
    mats[2].theta_s = 0.001;
    mats[2].min_Jp = -2;
    mats[2].max_Jp = 5;
    for (int m = 0; m < 3; ++m) material_derive(&mats[m]);

    Particles p;
    memset(&p, 0, sizeof p);
    const int n = 3000;
    double x[3] = {0, 0, 0}, v[3] = {0, 0, 0};
    for (int i = 0; i < n; ++i) CHECK(particles_push(&p, x, v, 1.0, 1.0, i % 3) == MPM_OK, "push");
    double *F0 = malloc(sizeof(double) * 9 * n);
    for (int i = 0; i < n; ++i) {
        double s[3], R1[9], R2[9];
        for (int k = 0; k < 3; ++k) s[k] = test_uniform(&rng, 0.97, 1.03);
        compose(s, R1, R2, p.F + 9 * i);
    }
    memcpy(F0, p.F, sizeof(double) * 9 * n);

    /* Snow hardening without plastic state: error, nothing changed. (Without
     * hardening Jp is never read, so no storage is needed.) */
    mats[2].hardening = 10;
    mpm_clear_error();
    CHECK(plasticity_apply(&p, mats, 3) == MPM_EINTERNAL, "snow hardening without Jp must fail");
    CHECK(strlen(mpm_last_error()) > 0, "error message recorded");
    CHECK(memcmp(F0, p.F, sizeof(double) * 9 * n) == 0, "failed apply changed F");
    mats[2].hardening = 0;

    CHECK(particles_enable_plastic_state(&p) == MPM_OK, "enable Jp");
    /* Bad material index: error, nothing changed. */
    p.mat[17] = 3;
    mpm_clear_error();
    CHECK(plasticity_apply(&p, mats, 3) == MPM_EINTERNAL, "bad material index must fail");
    CHECK(strstr(mpm_last_error(), "17") != NULL, "message names the particle: %s", mpm_last_error());
    CHECK(memcmp(F0, p.F, sizeof(double) * 9 * n) == 0, "failed apply changed F");
    p.mat[17] = 17 % 3;
    /* Invalid material parameters. */
    mats[1].yield_stress = -1;
    CHECK(plasticity_apply(&p, mats, 3) == MPM_EINTERNAL, "negative yield stress must fail");
    mats[1].yield_stress = 720;

    mpm_clear_error();
    CHECK(plasticity_apply(&p, mats, 3) == MPM_OK, "apply: %s", mpm_last_error());
    int n_vm = 0, n_snow = 0;
    for (int i = 0; i < n; ++i) {
        double F[9], Jp = 1.0;
        m3_copy(F, F0 + 9 * i);
        const Material *mt = &mats[i % 3];
        int r = 0;
        if (mt->plasticity == PLASTICITY_VON_MISES) n_vm += r = plasticity_von_mises(F, mt->mu, mt->lambda, 720);
        if (mt->plasticity == PLASTICITY_SNOW) n_snow += r = plasticity_snow(F, &Jp, 0.01, 0.001, -2, 5);
        CHECK(memcmp(F, p.F + 9 * i, sizeof F) == 0, "particle %d: F differs from the direct rule", i);
        CHECK(Jp == p.Jp[i], "particle %d: Jp %g vs %g", i, p.Jp[i], Jp);
        (void)r;
    }
    CHECK(n_vm > 100 && n_snow > 100, "coverage: %d von Mises, %d snow projections", n_vm, n_snow);
    free(F0);
    particles_free(&p);

    /* Empty set and no-plastic-material set are fine. */
    Particles e;
    memset(&e, 0, sizeof e);
    CHECK(plasticity_apply(&e, mats, 3) == MPM_OK, "empty particle set");
    CHECK(plasticity_apply(NULL, mats, 3) == MPM_EINTERNAL, "NULL particles");
}

int main(void)
{
    test_von_mises();
    test_snow();
    test_apply();
    return test_summary("test_plasticity");
}
