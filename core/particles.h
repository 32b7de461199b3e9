/* Particle storage, structure of arrays. Vector fields are stored per field
 * (x holds 3 doubles per particle, F holds 9, row-major). */
#ifndef MPM_PARTICLES_H
#define MPM_PARTICLES_H

#include <stddef.h>

typedef struct {
    size_t n, cap;
    double *x;    /* 3n positions [m] */
    double *v;    /* 3n velocities [m/s] */
    double *C;    /* 9n APIC affine matrices [1/s] */
    double *F;    /* 9n deformation gradients */
    double *mass; /* n [kg] */
    double *vol;  /* n rest volumes [m^3] */
    int *mat;     /* n material index into the scene's materials */
    double *Jp;   /* n plastic volume ratio (snow hardening); NULL unless a material needs it */
    size_t *id;   /* n identities: the particle's index when it was pushed (0, 1, ...; particles are
                     never removed), kept through particles_permute and particles_copy, so runs
                     can be compared particle by particle (experiments/accuracy/trajectory.h) */
} Particles;

/* Grows capacity to at least `cap` (keeps contents). */
int particles_reserve(Particles *p, size_t cap);
/* Appends one particle with F = I, C = 0, id = its index. */
int particles_push(Particles *p, const double x[3], const double v[3], double mass, double vol, int mat);
/* Allocates the plastic state array (Jp = 1) if absent. */
int particles_enable_plastic_state(Particles *p);
/* Copies src into dst (grown as needed; dst's plastic state is allocated
 * when src has one). */
int particles_copy(Particles *dst, const Particles *src);
/* Reorders particles: new index k holds old particle perm[k]. `scratch` must
 * hold 9n doubles. */
void particles_permute(Particles *p, const size_t *perm, double *scratch);
void particles_free(Particles *p);

#endif
