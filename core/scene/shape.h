/* Solid shapes as signed-distance-style level sets: phi(x) < 0 inside,
 * phi(x) > 0 outside, phi = 0 on the surface.
 *
 * For the primitives phi is the exact Euclidean signed distance, except the
 * ellipsoid (an approximation with the exact sign). CSG combinations use
 * min/max (union: min, intersection: max, difference: max(a, -b, ...)),
 * which keep the exact sign; for every shape |phi| never exceeds the true
 * distance to the surface (a conservative bound, which the volume estimator
 * relies on).
 *
 * JSON form (one object; unknown fields are errors):
 *   {"type": "box",        "min": [x,y,z], "max": [x,y,z]}
 *   {"type": "sphere",     "center": [..], "radius": r}
 *   {"type": "cylinder",   "center": [..], "radius": r, "height": h,   capped; h = full height
 *                          "axis": "x"|"y"|"z"|[ax,ay,az]}             default "y"
 *   {"type": "torus",      "center": [..], "major_radius": R, "minor_radius": r,
 *                          "axis": "x"|"y"|"z"|[..]}                   hole axis, default "y"
 *   {"type": "ellipsoid",  "center": [..], "radii": [a,b,c]}           axis-aligned radii
 *   {"type": "capsule",    "a": [..], "b": [..], "radius": r}          segment a-b swept by a ball
 *   {"type": "half_space", "point": [..], "normal": [..]}
 *        phi = (x - point) . n / |n|: the solid is the side OPPOSITE the normal,
 *        i.e. "normal" is the outward normal of the solid. A ground solid for
 *        y <= 0.1 is {"type":"half_space","point":[0,0.1,0],"normal":[0,1,0]}.
 *   {"type": "mesh",       "file": "wheel.obj", "max_boundary_edges": 0}
 *        closed OBJ mesh (core/scene/mesh.h); a relative path is relative to the
 *        asset directory; max_boundary_edges (default 0) admits nearly
 *        closed meshes.
 *   {"type": "union"|"intersection"|"difference", "shapes": [shape, ...]}
 *        difference = first shape minus all the others.
 * Every shape may also carry a transform, applied in this order:
 *   "scale": s           uniform, s > 0, about the pivot
 *   "rotate_deg": [rx, ry, rz]   rotation about x, then about y, then about z
 *                        (R = Rz Ry Rx), about the pivot
 *   "translate": [tx, ty, tz]
 *   "pivot": [..]        the point scale and rotation keep fixed. Default: the
 *                        primitive's centre (box: midpoint, capsule: midpoint
 *                        of a-b, half_space: point), the file origin (0,0,0)
 *                        for a mesh, the centre of the untransformed bounds
 *                        for CSG.
 *   world x = pivot + translate + s R (X - pivot), X in the shape's own frame;
 *   phi_world(x) = s phi_own(X).
 */
#ifndef MPM_SHAPE_H
#define MPM_SHAPE_H

#include <jansson.h>
#include <stddef.h>

#include "core/level_set.h"

typedef struct Shape Shape;

/* Parses one shape. `file` and `jpath` (the dot path of `j` in the scene,
 * e.g. "objects.0.shape") only name the place in error messages, which read
 * "<file>: <jpath>.radius: expected a positive number, got -1". `asset_dir`
 * (nullable) resolves relative mesh paths (NULL: relative to the working
 * directory). `dx` is the scene's grid spacing (reserved for resolution-
 * dependent shapes; any positive value is fine). */
int shape_parse(json_t *j, const char *file, const char *jpath, const char *asset_dir, double dx,
                Shape **out);

/* Signed distance (approximate for ellipsoids), <= 0 inside. Thread-safe. */
double shape_sdf(const Shape *s, const double x[3]);

/* Inside test, the same as shape_sdf(s, x) <= 0 but cheaper for meshes
 * (winding number only, no distance). Thread-safe. */
int shape_contains(const Shape *s, const double x[3]);

/* Conservative world-space axis-aligned bounds; +-HUGE_VAL on unbounded
 * sides (half-spaces, unions with them). */
void shape_bounds(const Shape *s, double lo[3], double hi[3]);

/* The bounds the HOT authors' code gives the shape, for the reference CFL
 * rule (collider_max_speed_reference): an untransformed cylinder is bounded
 * by the box of its circumscribed sphere, centre +- sqrt(r^2 + (h/2)^2) on
 * every axis (this reproduces their bar3 dt 0.0024565 s, SPEC 12); every
 * other shape by shape_bounds. */
void shape_reference_bounds(const Shape *s, double lo[3], double hi[3]);

/* 1 if every side of the bounds is finite. */
int shape_is_bounded(const Shape *s);

/* A cheap upper bound of the volume (for budgets before sampling): exact for
 * primitives and meshes, for CSG the sum (union), smallest (intersection)
 * or first (difference) of the children's bounds, never above the bounding
 * box's volume. HUGE_VAL when unbounded. */
double shape_volume_bound(const Shape *s);

/* Volume: exact for primitives (times scale^3), the mesh's enclosed volume
 * for meshes, and for CSG a deterministic adaptive-octree estimate (relative
 * error well below 1% for smooth shapes; see shape.c). HUGE_VAL when
 * unbounded. */
double shape_volume(const Shape *s);

/* For a "mesh" shape: copies of all its vertices (file order) in world
 * coordinates, transform applied, as a malloc'ed array of 3 *n doubles
 * (free it). MPM_EINPUT for other shape types. */
int shape_mesh_vertices(const Shape *s, double **xyz, size_t *n);

/* Type name as in JSON ("box", "union", ...). */
const char *shape_type_name(const Shape *s);

void shape_free(Shape *s);

/* The shape as a core level set (colliders and sources hold one); the level
 * set owns s (level_set_free frees it). NULL gives an empty level set. */
LevelSet shape_level_set(Shape *s);

#endif
