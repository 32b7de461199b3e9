/* Particle sources: material poured into the scene while it runs (HOT's
 * SourceCollisionObject, docs/scenes.md §4, hot-scenes.md sections 3.6 Boards and
 * 3.9 Sauce).
 *
 * The JSON form is in core/scene/source_load.h.
 *
 * Emission (as in the reference): the shape's rest-frame bounds are filled
 * (by the loader) with samples of the scene's periodic Poisson tile at the source's ppc. At
 * time t every sample is displaced by D(t) = velocity (t - from), wrapping
 * periodically along each axis the velocity moves; the wrap period is a
 * whole number of tile periods, so the moving pattern stays blue noise
 * without a seam (the reference wraps in the shape's bounding cube).
 * After a step [t0, t0 + dt] that begins inside the window
 * (from <= t0 < until, with a 1e-9 relative tolerance so that an "until"
 * on a frame boundary behaves like the reference's frame test), every
 * sample that was inside the shape at its (wrapped) position X at D(t0)
 * and is outside at X + velocity dt becomes a particle there, at its
 * world position at t0 + dt (the
 * source's pose at that time applied to the rest-frame sample), with
 * velocity R(t0 + dt) velocity (the source's own motion is not added, as
 * in the reference), F = I, C = 0, Jp = 1 when plastic state is stored,
 * rest volume V_p and mass density V_p. Particles are appended in sample
 * order, so emission is deterministic and independent of the thread count.
 * Outside the window a source does no work at all.
 *
 * Rest volume: "sampled" (default) gives V_p = dx^3 / (0.868 ppc), the
 * volume per sample of the realised Poisson density, so the emitted mass is
 * density x the swept volume; "nominal" gives the reference's dx^3 / ppc
 * (13 % lighter at the same count).
 *
 * The emitted count over a window of length T is about
 * 0.868 ppc / dx^3 x (area of the shape's cross-section normal to the
 * velocity) x |velocity| T; e.g. HOT's Boards (r = 0.03 m, 0.5 m/s, 4.125 s,
 * dx = 0.007 m, ppc 16) gives about 236k particles.
 *
 * Collider: unless "collider" is false, the scene also adds a sticky
 * collider named after the source (in the colliders array after the scene's
 * own colliders, before the domain walls): the same shape and motion, with
 * "material_velocity" = velocity (so grid nodes inside move with the
 * source's motion plus the outflow velocity) and "cfl_speed" = |velocity|
 * (the reference's source reports only its material speed to the CFL
 * rule). It stays in place after the emission window, as in the reference.
 * A source without a collider reports no speed to the CFL rule (its emitted
 * particles do, once they exist). */
#ifndef MPM_SOURCE_H
#define MPM_SOURCE_H

#include <stddef.h>

#include "core/collider.h"
#include "core/material.h"
#include "core/particles.h"

typedef struct Source {
    char name[64];
    int mat;                  /* material index */
    double ppc;
    double velocity[3];       /* rest frame, m/s */
    double from, until;       /* emission window [s]; until = HUGE_VAL: forever */
    double vol, mass;         /* per emitted particle */
    Collider pose;            /* the shape and its motion (not a scene collider) */
    double *X;                /* n rest-frame samples at D = 0 */
    size_t n;
    int wrap[3];              /* axes along which samples move (velocity != 0) */
    double box_lo[3], period[3]; /* wrap box on those axes */
    int has_collider;
} Source;

/* 1 if a step beginning at t0 emits (from <= t0 < until, see above). */
int source_active(const Source *s, double t0);

/* Emits the particles of the step [t0, t0 + dt] (nothing outside the
 * window) and appends them to p; *n_emitted (nullable) receives their
 * number. */
int source_emit(const Source *s, Particles *p, double t0, double dt, size_t *n_emitted);

/* source_emit for every source, in order. */
int source_emit_all(const Source *src, int n_src, Particles *p, double t0, double dt);

/* Samples examined by source_emit since the process started (a counter for
 * tests: it does not grow outside the emission windows). */
unsigned long long source_samples_examined(void);

void source_free(Source *s);

#endif
