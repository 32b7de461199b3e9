/* Loading scenes: JSON files describing one benchmark problem (the loaded
 * Scene is core/scene_description.h). The built-in scenes
 * are experiments/scenes/NAME.json; nothing is hard-coded in C.
 *
 * ------------------------------------------------------------------------
 * Scene file format (SI units, y up). Unknown fields anywhere are errors.
 * ------------------------------------------------------------------------
 * {
 *   "name": "bar3",                   required, 1-63 characters
 *   "description": "...",             optional
 *   "dx": 0.0075,                     required, grid spacing [m] (> 0), times --scale
 *   "fps": 48,                        required, frames per second (> 0)
 *   "frames": 48,                     required, integer >= 1
 *   "cfl": 0.6,                       optional (default 0.6), > 0
 *   "max_dt": 0.0208333,              optional (default 1/fps), >= min_dt
 *   "min_dt": 1e-6,                   optional (default 1e-6 s, the reference's
 *                                     floor), <= 1/fps and >= 1/fps / 1e6: a
 *                                     step whose CFL dt falls below it fails
 *                                     (MPM_ENUMERIC) instead of silently
 *                                     violating the CFL limit
 *   "cfl_rule": "paper",              optional: which collider speed the CFL
 *                                     dt sees (SPEC 12): "paper" (default)
 *                                     the colliders' largest surface speed
 *                                     over the particle bounding box grown
 *                                     by 4 dx; "reference" also counts the
 *                                     corners of each collider's own
 *                                     bounding box as the HOT authors' code
 *                                     does (collider_max_speed_reference)
 *   "gravity": [0, -9.8, 0],          required, m/s^2
 *   "apic_ratio": 1,                  optional (default 1): APIC/RPIC blend r in
 *                                     [0, 1]; 1 = APIC, 0 = RPIC. Read by the
 *                                     APIC transfer only (PIC/FLIP keeps no
 *                                     affine matrix), so "transfer" can be
 *                                     switched with --set on any scene
 *   "transfer": "apic",               optional: "apic" (default, APIC/RPIC) |
 *                                     "mls" (MLS-MPM, SPEC 9: APIC velocities,
 *                                     grad w_ip replaced by w_ip 4/dx^2 (x_i -
 *                                     x_p) in the force, the F update and the
 *                                     potential's derivatives; Hu et al.
 *                                     2018) | "pic_flip" | {"type": "pic_flip",
 *                                     "alpha": 0.95}: v_p = alpha v_FLIP +
 *                                     (1 - alpha) v_PIC and C_p = 0
 *                                     (Stomakhin et al. 2013; Gast et al.
 *                                     2015 section 6.1 step 5), alpha in
 *                                     [0, 1], default 0.95 (Gast's value;
 *                                     0 = PIC, 1 = FLIP), see core/transfer.h
 *   "position_update": "forward_euler",
 *                                     optional: "forward_euler" (default,
 *                                     x_p += dt v_PIC) | "backward_euler":
 *                                     x_p^{n+1} = x_p^n + dt v(x_p^{n+1}) by
 *                                     per-particle Newton (Gast 2015 section
 *                                     6.3, core/position_update.h)
 *   "particle_volume": "shape",       optional: "shape" (default, see
 *                                     "Particles" below) | "grid_density":
 *                                     at the first step V_p = m_p / rho_p with
 *                                     rho_p = sum_i w_ip m_i / dx^3 (Gast 2015
 *                                     section 6.1 step 2; core/transfer.h);
 *                                     particles emitted later keep their
 *                                     source's volume
 *   "domain": {"min": [..], "max": [..]},   required; every particle must lie
 *                                     in it (max > min on every axis)
 *   "domain_walls": true,             optional (default false): adds six sticky
 *                                     half-space colliders at the domain faces
 *                                     (named wall_x_min, ..., wall_z_max), like
 *                                     the reference's safety walls
 *   "seed": 1,                        optional (default 1), integer >= 0: seeds
 *                                     the Poisson tile, random sampling and
 *                                     random initial F
 *   "materials": {                    required, at least one; declaration
 *     "NAME": {                       order = material index
 *       "E": 1e5,                     Young's modulus [Pa], > 0
 *       "nu": 0.3,                    Poisson ratio, -1 < nu < 0.5
 *       "density": 1000,              kg/m^3, > 0
 *       "plasticity": {"type": "none"}                       optional
 *                   | {"type": "von_mises", "yield_stress": tau_Y > 0}
 *                   | {"type": "snow", "theta_c": in (0,1), "theta_s": >= 0,
 *                      "hardening": >= 0 (default 0),
 *                      "min_Jp": (default 0), "max_Jp": (default 1e30)}
 *                     snow (Stomakhin et al. 2013, as Gast et al. 2015 use
 *                     it): singular values of the elastic F clamped to
 *                     [1 - theta_c, 1 + theta_s] after each step, the
 *                     plastic volume ratio J_p kept per particle, and mu,
 *                     lambda scaled by exp(hardening (1 - J_p)) in the step
 *                     problem (core/plasticity.h)
 *     }, ...
 *   },
 *   "objects": [                      required, at least one (may be empty
 *                                     when the scene has "sources")
 *     {"name": "...",                 optional label
 *      "material": "NAME",            required, a key of "materials"
 *      "shape": {...},                required, see core/scene/shape.h (must be bounded)
 *      "ppc": 8,                      required, > 0 particles per dx^3 cell
 *      "sampling": "poisson",         optional: "poisson" (default) | "random" |
 *                                     "lattice" (ppc = k^3), see core/scene/sampler.h
 *      "velocity": [0, 0, 0],         optional initial velocity [m/s]
 *      "initial_F": {"type": "random_diagonal", "min": 0.7, "max": 1.3,
 *                    "seed": 7, "per_particle": true}
 *                                     optional: F = diag(d0, d1, d2) with d_k
 *                                     uniform in [min, max] (0 < min <= max),
 *                                     per particle (default) or one for the
 *                                     whole object; seed defaults to one
 *                                     derived from the scene seed.
 *                   | {"type": "diagonal", "values": [1, 1, 1e-4]}
 *                                     F = diag(values) for every particle
 *                                     (non-zero finite entries, any sign: a
 *                                     degenerate or inverted start)
 *                     either with "inverted_fraction": f in [0, 1] (default
 *                                     0): each particle independently, with
 *                                     probability f (seeded), starts with d0
 *                                     negated, det F < 0 (an inverted state)
 *      "variation": {"amplitude": 0.1, "length": 0.02, "seed": 5}
 *                                     optional: a clumpy material. With the
 *                                     smooth value noise nu(x) in [-1, 1] of
 *                                     correlation length "length" [m] > 0
 *                                     (core/scene/noise.h), each particle's mass
 *                                     (density) is scaled by
 *                                     1 + amplitude nu(x_p), 0 <= amplitude
 *                                     < 1; if the material is snow with
 *                                     hardening, the particle also starts
 *                                     pre-compacted, J_p = 1 / (1 + amplitude
 *                                     nu) (the density ratio), so its Lame
 *                                     parameters are scaled by
 *                                     exp(xi (1 - J_p)): denser clumps are
 *                                     stiffer. "seed" (integer >= 0) defaults
 *                                     to one derived from the scene seed.
 *      "stiffness_variation": {"pattern": "checkerboard", "factor": 1e6, "cell": 0.01}
 *                                     optional: Young's modulus varying
 *                                     between neighbours. A twin of the
 *                                     object's material with E times
 *                                     "factor" (> 0), named "NAME*FACTOR"
 *                                     and added after the declared
 *                                     materials, is given to the particles
 *                                     in the odd cells of a checkerboard of
 *                                     "cell" [m] cubes (default: the scene's
 *                                     dx after --scale; odd = the sum of
 *                                     floor(x / cell) over the axes) or, with
 *                                     "pattern": "random", to each particle
 *                                     with probability 1/2 ("seed", default
 *                                     derived from the scene seed)
 *      "surface_particles": {"count": N} | {"vertices_of": {mesh shape}}
 *                                     optional: extra particles on the
 *                                     surface, standing in for the
 *                                     reference's .obj vertices that it adds
 *                                     as particles (hot-scenes.md 1.5).
 *                                     "count": N points spread uniformly by
 *                                     area over the shape's surface
 *                                     (core/scene/sampler.h sampler_surface);
 *                                     "vertices_of": the vertices of that
 *                                     mesh (transform applied). N (or the
 *                                     vertex count) is for --scale 1: at
 *                                     --scale s, round(N / s^3) are used
 *                                     (evenly spaced vertices in file order),
 *                                     so they keep their share of the count.
 *     }, ...
 *   ],
 *   "colliders": [ {...}, ... ]       optional, see core/scene/collider_load.h
 *   "sources": [ {...}, ... ]         optional, particle sources, see
 *                                     core/scene/source_load.h; each adds a sticky
 *                                     collider after "colliders" (before
 *                                     the domain walls) unless disabled
 * }
 *
 * Particles: each object is sampled independently (overlapping objects keep
 * both particle sets, as in the reference). Rest volume V_p = shape volume /
 * number of particles (interior samples plus surface particles, as the
 * reference does for analytic shapes with .obj vertices), mass =
 * density V_p (times 1 + amplitude nu(x_p) with "variation"), C = 0,
 * F = I unless initial_F. Surface particles come first
 * in each object (the reference prepends the vertices).
 *
 * Overrides (--set key=value) are applied to the JSON tree before validation.
 * The key is a dot path: object members by key, array elements by index
 * ("materials.middle.E", "colliders.1.motion.0.angular_velocity_deg.1",
 * "frames"). The value is parsed as JSON (number, bool, array, object,
 * quoted string) when it parses, else taken as a plain string. The path must
 * exist, except that a missing optional field may be created in an existing
 * top-level, material, plasticity, object or collider object.
 *
 * Particle budget: before sampling, each object's particle count is
 * estimated (sampling density x ppc x a volume bound / dx^3, plus surface
 * particles); a scene whose estimate, or whose sampled count, exceeds
 * SceneLoadOptions.max_particles fails with MPM_EINPUT naming the object,
 * its ppc and dx (the run command's --max-particles sets the budget).
 *
 * Errors: every validation failure returns MPM_EINPUT with one line naming
 * the file, the JSON path of the field, the bad value and what was expected,
 * e.g. "bar3.json: materials.middle.E: expected a positive number, got -5".
 */
#ifndef MPM_SCENE_LOAD_H
#define MPM_SCENE_LOAD_H

#include <stddef.h>

#include "core/scene_description.h"

typedef struct {
    const char *key;
    const char *value;
} SceneOverride; /* from --set key=value */

typedef struct {
    double scale;                     /* dx multiplier (0 means 1) */
    const SceneOverride *overrides;
    int n_overrides;
    const char *asset_dir;            /* relative mesh paths; NULL: the scene file's directory */
    size_t max_particles;             /* particle budget; 0: scene_default_max_particles() */
} SceneLoadOptions;

/* The default particle budget: the machine's physical memory / 16 KiB, the
 * peak memory per particle of the heaviest solver measured (pn-cholmod on
 * bar3, 20k particles: 343 MB; pn-pcg 118 MB, hot 129 MB). */
size_t scene_default_max_particles(void);

/* A particle budget given by `flag` ("--max-particles"): a positive integer
 * (1e6 notation accepted) up to 1e12, else MPM_EINPUT naming the flag. */
int scene_parse_particle_budget(const char *flag, const char *text, size_t *out);

/* Loads a built-in scene by name (no '/' and no ".json" suffix; looked up in
 * scene_dir()) or a scene
 * file by path. `opt` may be NULL (scale 1, no overrides). On failure *out
 * is left empty (scene_free is still safe). */
int scene_load(const char *name_or_path, const SceneLoadOptions *opt, Scene *out);
void scene_free(Scene *s);

/* The built-in scene directory in use: $MPM_SCENE_DIR, else share/mpmbench/scenes
 * found relative to the executable (core/scene/data_dir.h). */
const char *scene_dir(void);

typedef void (*SceneListFn)(const char *name, const char *description, void *ctx);
/* Calls fn for every built-in scene, sorted by name. */
int scene_list(SceneListFn fn, void *ctx);

#endif
