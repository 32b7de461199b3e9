/* Analytic level-set colliders with scripted rigid motion.
 *
 * A collider is a Shape (core/shape.h) in its rest frame plus a rigid
 * motion. The world position of rest-frame point X at time t is
 *
 *     x = R(t) (X - pivot0) + pivot0 + b(t),
 *
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
 * Example (HOT Fig. 20 top cap, 360 deg/s about +y for 1 s, then stopped):
 *   "motion": [{"until": 1.0, "angular_velocity_deg": [0, 360, 0]},
 *              {"velocity": [0, 0, 0]}]
 *
 * All evaluation functions are const and thread-safe: phase start poses are
 * precomputed at parse time, evaluation is O(number of phases). */
#ifndef MPM_COLLIDER_H
#define MPM_COLLIDER_H

#include <jansson.h>

#include "core/shape.h"

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

/* Rigid velocity of the collider material at world point x and time t
 * (zero while removed and after the last finite phase). */
void collider_velocity(const Collider *c, double t, const double x[3], double v[3]);

/* 0 during a "removed" phase, 1 otherwise. */
int collider_active(const Collider *c, double t);

/* Largest |velocity| of collider material in the box [lo, hi] (e.g. the
 * particle bounding box enlarged by a few dx), for the CFL time step: the
 * rigid speed |omega x r + v| is convex in x, so its maximum over a box is at
 * a corner. The box used is [lo, hi] intersected with the collider's current
 * world bounds when they overlap, else [lo, hi] itself. 0 when inactive. */
double collider_max_speed(const Collider *c, double t, const double lo[3], const double hi[3]);

void collider_free(Collider *c);

#endif
