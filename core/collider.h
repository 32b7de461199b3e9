/* Analytic level-set colliders with scripted rigid motion.
 *
 * A collider is a Shape (core/scene/shape.h) in its rest frame plus a rigid
 * motion. The world position of rest-frame point X at time t is
 *
 *     x = R(t) (X - pivot0) + pivot0 + b(t),
 *
 * (b(t) includes the optional oscillation below)
 * pivot0 = the "pivot" field, or by default the centre of the shape's bounds
 * (0 on the axes where the bounds are unbounded, e.g. half-spaces). b(t) integrates the translation velocity and R(t) the angular
 * velocity about the moving pivot p(t) = pivot0 + b(t); the collider
 * material moves with v(x) = omega x (x - p(t)) + v_translation.
 *
 * JSON form (unknown fields are errors):
 *   {"name": "top_cap",                   optional, default "collider<i>"
 *    "type": "sticky" | "slip",           optional, default "sticky"
 *    "shape": {...},                      required, see shape.h
 *    "pivot": [x, y, z],                  optional
 *    "motion": [phase, ...]}              optional, default: static forever
 *    "oscillation": {...},                optional, see below
 *    "material_velocity": [vx, vy, vz],   optional, default 0
 *    "cfl_speed": s,                      optional
 *    "friction": mu}                      optional, default 0: Coulomb
 *                                         friction coefficient (>= 0) of a
 *                                         "slip" collider (a sticky one
 *                                         already takes the collider's
 *                                         velocity; friction > 0 there is an
 *                                         error), see collider_friction
 *   phase = {"until": t_end,              seconds, absolute time; omit or null
 *                                         only on the last phase (= forever)
 *            "velocity": [vx, vy, vz],     m/s, default 0
 *            "angular_velocity_deg": [wx, wy, wz],  deg/s about the moving
 *                                         pivot (world-frame axis), default 0
 *            "removed": true}             optional: the collider is inactive
 *                                         during this phase (pushers taken away)
 *   A phase runs from the previous phase's "until" (0 for the first) to its
 *   own "until"; the pose is continuous across phases (each phase composes an
 *   exact rotation exp(omega tau) onto the pose it starts from). If the last
 *   phase has an "until", the collider stays at rest (not removed) at its
 *   final pose afterwards. Times before 0 use the first phase.
 *
 * "oscillation": {"amplitude": [ax, ay, az],             m, default 0
 *                 "angular_frequency_deg": [wx, wy, wz], deg/s, default 0
 *                 "phase_deg": [px, py, pz]}             deg, default 0
 *   adds a sinusoidal translation b_osc(t) with components
 *   a_k sin(w_k t + p_k) (world axes, absolute time t) on top of the phases,
 *   e.g. HOT's Sauce source whose centre is
 *   (3 - 0.4 sin(55 deg/s t), 4.18, 2.857 + 0.5 sin(120 deg/s t)):
 *   "oscillation": {"amplitude": [-0.4, 0, 0.5],
 *                   "angular_frequency_deg": [55, 0, 120]}.
 *   It applies in every phase (a "removed" phase still removes the collider).
 * "material_velocity": velocity of the collider's material relative to its
 *   rigid motion, in the rest frame (world value R(t) v_m); added to
 *   collider_velocity, so sticky nodes inside move with it (the reference's
 *   R s v_material term; particle sources use it for their outflow).
 * "cfl_speed": the speed the collider reports to the CFL rule
 *   (collider_max_speed) instead of its material speed; the reference's
 *   source objects report only their material speed (0.5 m/s).
 *
 * Example (HOT Fig. 20 top cap, 360 deg/s about +y for 1 s, then stopped):
 *   "motion": [{"until": 1.0, "angular_velocity_deg": [0, 360, 0]},
 *              {"velocity": [0, 0, 0]}]
 *
 * All evaluation functions are const and thread-safe: phase start poses are
 * precomputed at parse time, evaluation is O(number of phases). */
#ifndef MPM_COLLIDER_H
#define MPM_COLLIDER_H

#include <jansson.h>

#include "core/scene/shape.h"

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
    Shape *shape;          /* rest frame */
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

/* Parses one collider object. `file`/`jpath` name it in error messages
 * ("<file>: colliders.1.motion.0.until: ..."). On failure *out is left
 * zeroed (nothing to free). `default_name` (nullable) names an unnamed
 * collider. */
int collider_parse(json_t *j, const char *file, const char *jpath, const char *asset_dir, double dx,
                   Collider *out);
/* Same with an explicit default name. */
int collider_parse_named(json_t *j, const char *file, const char *jpath, const char *asset_dir, double dx,
                         const char *default_name, Collider *out);

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
