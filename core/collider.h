/* Analytic level-set colliders with scripted rigid motion.
 *
 * A collider is a level set (core/level_set.h) in its rest frame plus a rigid
 * motion. The world position of rest-frame point X at time t is
 *
 *     x = R(t) (X - pivot0) + pivot0 + b(t),
 *
 * (b(t) includes the optional oscillation, core/scene/collider_load.h)
 * pivot0 = the "pivot" field, or by default the centre of the shape's bounds
 * (0 on the axes where the bounds are unbounded, e.g. half-spaces). b(t) integrates the translation velocity and R(t) the angular
 * velocity about the moving pivot p(t) = pivot0 + b(t); the collider
 * material moves with v(x) = omega x (x - p(t)) + v_translation.
 *
 * The JSON form (phases, oscillation, material velocity, cfl speed, friction)
 * is in core/scene/collider_load.h.
 *
 * All evaluation functions are const and thread-safe: phase start poses are
 * precomputed at load time, evaluation is O(number of phases). */
#ifndef MPM_COLLIDER_H
#define MPM_COLLIDER_H

#include "core/level_set.h"

typedef enum { COLLIDER_STICKY = 0, COLLIDER_SLIP = 1 } ColliderKind;

typedef struct {
    double t_start, t_end; /* t_end = HUGE_VAL for a final open phase */
    double vel[3];         /* m/s */
    double omega[3];       /* rad/s */
    int removed;
    double R0[9], b0[3];   /* pose at t_start */
} ColliderPhase;

typedef struct Collider {
    char name[64];
    ColliderKind kind;
    LevelSet shape;        /* rest frame */
    double pivot0[3];
    ColliderPhase *phases; /* n_phases >= 1 */
    int n_phases;
    double fd_h;           /* finite-difference step for normals (1e-3 dx) */
    int has_osc;
    double osc_amp[3], osc_omega[3], osc_phase[3]; /* m, rad/s, rad */
    double material_vel[3]; /* rest frame, m/s */
    double cfl_speed;      /* < 0: report the material speed (default) */
    double friction;       /* Coulomb coefficient mu of a slip collider (0: frictionless) */
} Collider;

/* Precomputes each phase's starting pose (R0, b0) from the phases' times and
 * velocities, the first phase starting at the identity: a loader calls it
 * once the phases are filled in. */
void collider_init_poses(Collider *c);

/* Pose at time t: x = R (X - pivot0) + pivot0 + b. */
void collider_pose(const Collider *c, double t, double R[9], double b[3]);

/* Level set at world x and time t: <= 0 inside the solid. `normal`
 * (nullable) receives the outward unit normal (central differences of the
 * SDF, rotated to world); zero where the gradient vanishes. An inactive
 * ("removed") collider returns HUGE_VAL and a zero normal. */
double collider_phi(const Collider *c, double t, const double x[3], double normal[3]);

/* Velocity of the collider material at world point x and time t: the rigid
 * motion omega x (x - p(t)) + db/dt (oscillation included) plus the
 * material velocity R(t) v_m. Zero while removed; after the last finite
 * phase only the oscillation and the material velocity remain. */
void collider_velocity(const Collider *c, double t, const double x[3], double v[3]);

/* 0 during a "removed" phase, 1 otherwise. */
int collider_active(const Collider *c, double t);

/* Largest |velocity| of collider material in the box [lo, hi] (e.g. the
 * particle bounding box enlarged by a few dx), for the CFL time step: the
 * rigid speed |omega x r + v| is convex in x, so its maximum over a box is at
 * a corner. The box used is [lo, hi] intersected with the collider's current
 * world bounds when they overlap, else [lo, hi] itself. 0 when inactive;
 * "cfl_speed" when the collider has one. A NaN speed is returned as NaN. */
double collider_max_speed(const Collider *c, double t, const double lo[3], const double hi[3]);

/* Coulomb friction at one grid node, applied to the grid velocity v^{n+1}
 * after the solve and before G2P (Stomakhin et al. 2013 section 8 applies it
 * to the grid velocities in its collision step; Gast et al. 2015 section
 * 5.1 applies it after the Newton solve, with the collision impulse taken
 * from the solve): with the relative velocity v_rel = v - v_col split
 * into its normal part (v_rel.n) n and tangential part v_t, and jn >= 0 the
 * normal collision impulse per unit mass (a velocity; for a node of a slip
 * collider, the normal component of the unconstrained gradient at the
 * solution divided by the node mass, the velocity change the constraint
 * made),
 *     v_t <- max(0, 1 - mu jn / |v_t|) v_t
 * (Gast eq. in section 5.1), i.e. |v_t| drops by exactly mu jn, or to 0
 * (sticking) if |v_t| <= mu jn; the normal part is untouched. jn <= 0 (the
 * constraint pulls, no contact pressure) leaves v alone. v is updated in
 * place. Returns 0 (untouched), 1 (tangential speed reduced) or 2 (stuck).
 * The relative kinetic energy 1/2 |v_rel|^2 never increases. */
int collider_friction(const double normal[3], const double v_col[3], double mu, double jn, double v[3]);

/* The reference's variant of collider_max_speed (scene "cfl_rule":
 * "reference", SPEC 12): also the speeds at the corners of the collider's
 * own bounding box that pass the reference's any-axis overlap test. */
double collider_max_speed_reference(const Collider *c, double t, const double lo[3], const double hi[3]);

void collider_free(Collider *c);

#endif
