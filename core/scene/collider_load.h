/* Reading a collider from its JSON object (core/collider.h is the runtime
 * object: pose, level set, velocity, friction).
 *
 * JSON form (unknown fields are errors):
 *   {"name": "top_cap",                   optional, default "collider<i>"
 *    "type": "sticky" | "slip",           optional, default "sticky"
 *    "shape": {...},                      required, see core/scene/shape.h
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
 *   The phases' start poses are precomputed here (collider_init_poses). */
#ifndef MPM_COLLIDER_LOAD_H
#define MPM_COLLIDER_LOAD_H

#include <jansson.h>

#include "core/collider.h"

/* Parses one collider object. `file`/`jpath` name it in error messages
 * ("<file>: colliders.1.motion.0.until: ..."). On failure *out is left
 * zeroed (nothing to free). `default_name` (nullable) names an unnamed
 * collider. */
int collider_parse(json_t *j, const char *file, const char *jpath, const char *asset_dir, double dx,
                   Collider *out);
/* Same with an explicit default name. */
int collider_parse_named(json_t *j, const char *file, const char *jpath, const char *asset_dir, double dx,
                         const char *default_name, Collider *out);

#endif
