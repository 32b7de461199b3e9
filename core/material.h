/* A material as a scene names it: elastic constants, density, plasticity. */
#ifndef MPM_MATERIAL_H
#define MPM_MATERIAL_H

typedef enum { PLASTICITY_NONE = 0, PLASTICITY_VON_MISES, PLASTICITY_SNOW } PlasticityKind;

typedef struct {
    char name[64];
    double E, nu, density;  /* Pa, -, kg/m^3 */
    double mu, lambda;      /* derived from E, nu (fcr_lame) */
    double stiffness;       /* a_p = ||dP/dF(I)||_F, derived (SPEC 4) */
    PlasticityKind plasticity;
    double yield_stress;    /* von Mises: Kirchhoff yield stress tau_Y [Pa] */
    double theta_c, theta_s; /* snow: singular values clamped to [1-theta_c, 1+theta_s] */
    double hardening;       /* snow: hardening coefficient xi (0 = none) */
    double min_Jp, max_Jp;  /* snow: clamp of the plastic volume ratio for hardening */
} Material;

/* Fills mu, lambda and stiffness from E and nu. */
void material_derive(Material *m);

#endif
