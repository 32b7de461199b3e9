/* Level-set shapes: primitives, CSG, affine transforms. See shape.h for
 * the JSON form.
 *
 * Distance formulas are the standard closed forms for each primitive
 * (e.g. Hart, "Sphere tracing", The Visual Computer 1996, for the box,
 * cylinder, torus and capsule distances); they are derived again here in
 * comments where the derivation is short. */
#include "core/scene/shape.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/scene/box_tree.h"
#include "core/error.h"
#include "core/mat3.h"
#include "core/scene/json_read.h"

#if __has_include("core/scene/mesh.h") && !defined(MPM_NO_MESH)
#include "core/scene/mesh.h"
#define MPM_HAVE_MESH 1
#else
#define MPM_HAVE_MESH 0
typedef struct Mesh Mesh;
#endif

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef enum {
    SH_BOX,
    SH_SPHERE,
    SH_CYLINDER,
    SH_TORUS,
    SH_ELLIPSOID,
    SH_CAPSULE,
    SH_HALF_SPACE,
    SH_MESH,
    SH_UNION,
    SH_INTERSECTION,
    SH_DIFFERENCE
} ShapeType;

static const char *const k_type_names[] = {"box",     "sphere",     "cylinder", "torus",
                                           "ellipsoid", "capsule", "half_space", "mesh",
                                           "union",   "intersection", "difference"};

struct Shape {
    ShapeType type;
    /* Own-frame parameters. c: centre (box, sphere, cylinder, torus,
     * ellipsoid), point (half-space). h: box half extents or ellipsoid radii.
     * axis: unit cylinder/torus axis or half-space normal. */
    double c[3], h[3], axis[3];
    double r;       /* radius; torus minor radius */
    double R;       /* torus major radius */
    double half_h;  /* cylinder half height */
    double a[3], b[3]; /* capsule segment */
    Mesh *mesh;
    Shape **kids;
    int n_kids;
    BoxTree *kid_tree; /* unions of many shapes: a hierarchy over the kids' bounds */
    /* Transform: x = pivot + t + s Rot (X - pivot). */
    int has_xf, has_rot;
    double pivot[3], t[3], s, rot[9];
    /* World bounds (cached at parse time). */
    double lo[3], hi[3];
};

/* ======================================================================
 * Distances in the shape's own frame
 * ====================================================================== */

static inline double sq(double x) { return x * x; }

/* Exact box distance: with q = |p| - h per axis, the outside distance is the
 * length of max(q, 0) and the inside distance is -min_k(-q_k). */
static double sdf_box(const Shape *s, const double X[3])
{
    double q[3], out2 = 0.0, qmax = -DBL_MAX;
    for (int k = 0; k < 3; ++k) {
        q[k] = fabs(X[k] - s->c[k]) - s->h[k];
        if (q[k] > 0) out2 += q[k] * q[k];
        if (q[k] > qmax) qmax = q[k];
    }
    return sqrt(out2) + (qmax < 0 ? qmax : 0.0);
}

/* Capped cylinder: in the (radial, axial) half plane it is a rectangle
 * [0, r] x [-H/2, H/2], so the same box formula applies in 2D. */
static double sdf_cylinder(const Shape *s, const double X[3])
{
    double d[3] = {X[0] - s->c[0], X[1] - s->c[1], X[2] - s->c[2]};
    double y = v3_dot(d, s->axis);
    double rad = sqrt(fmax(v3_dot(d, d) - y * y, 0.0));
    double qx = rad - s->r, qy = fabs(y) - s->half_h;
    double out = sqrt(sq(fmax(qx, 0.0)) + sq(fmax(qy, 0.0)));
    return out + fmin(fmax(qx, qy), 0.0);
}

/* Torus: distance to the core circle (radius R in the plane normal to the
 * axis) minus the tube radius. */
static double sdf_torus(const Shape *s, const double X[3])
{
    double d[3] = {X[0] - s->c[0], X[1] - s->c[1], X[2] - s->c[2]};
    double y = v3_dot(d, s->axis);
    double rho = sqrt(fmax(v3_dot(d, d) - y * y, 0.0));
    return sqrt(sq(rho - s->R) + y * y) - s->r;
}

/* Ellipsoid: phi = r_min (|p / radii| - 1). Its sign is exact, its zero set
 * is the ellipsoid, its gradient on the surface is parallel to the true
 * normal (grad |p/radii| ~ p / radii^2), and |phi| <= true distance because
 * the map p -> p / radii is Lipschitz with constant 1 / r_min. */
static double sdf_ellipsoid(const Shape *s, const double X[3])
{
    double k0 = 0.0, rmin = fmin(s->h[0], fmin(s->h[1], s->h[2]));
    for (int k = 0; k < 3; ++k) k0 += sq((X[k] - s->c[k]) / s->h[k]);
    return rmin * (sqrt(k0) - 1.0);
}

/* Capsule: distance to the segment a-b minus the radius. */
static double sdf_capsule(const Shape *s, const double X[3])
{
    double pa[3] = {X[0] - s->a[0], X[1] - s->a[1], X[2] - s->a[2]};
    double ba[3] = {s->b[0] - s->a[0], s->b[1] - s->a[1], s->b[2] - s->a[2]};
    double bb = v3_dot(ba, ba);
    double h = bb > 0 ? v3_dot(pa, ba) / bb : 0.0;
    h = h < 0 ? 0 : (h > 1 ? 1 : h);
    double d[3] = {pa[0] - h * ba[0], pa[1] - h * ba[1], pa[2] - h * ba[2]};
    return v3_norm(d) - s->r;
}

static double kid_sdf(const void *ctx, int k, const double X[3])
{
    return shape_sdf(((const Shape *)ctx)->kids[k], X);
}

static int kid_contains(const void *ctx, int k, const double X[3])
{
    return shape_contains(((const Shape *)ctx)->kids[k], X);
}

static double sdf_local(const Shape *s, const double X[3])
{
    switch (s->type) {
    case SH_BOX: return sdf_box(s, X);
    case SH_SPHERE: {
        double d[3] = {X[0] - s->c[0], X[1] - s->c[1], X[2] - s->c[2]};
        return v3_norm(d) - s->r;
    }
    case SH_CYLINDER: return sdf_cylinder(s, X);
    case SH_TORUS: return sdf_torus(s, X);
    case SH_ELLIPSOID: return sdf_ellipsoid(s, X);
    case SH_CAPSULE: return sdf_capsule(s, X);
    case SH_HALF_SPACE: {
        double d[3] = {X[0] - s->c[0], X[1] - s->c[1], X[2] - s->c[2]};
        return v3_dot(d, s->axis);
    }
    case SH_MESH:
#if MPM_HAVE_MESH
        return mesh_signed_distance(s->mesh, X);
#else
        return HUGE_VAL;
#endif
    case SH_UNION: {
        if (s->kid_tree) return box_tree_min(s->kid_tree, X, kid_sdf, s);
        double p = HUGE_VAL;
        for (int k = 0; k < s->n_kids; ++k) p = fmin(p, shape_sdf(s->kids[k], X));
        return p;
    }
    case SH_INTERSECTION: {
        double p = -HUGE_VAL;
        for (int k = 0; k < s->n_kids; ++k) p = fmax(p, shape_sdf(s->kids[k], X));
        return p;
    }
    case SH_DIFFERENCE: {
        double p = shape_sdf(s->kids[0], X);
        for (int k = 1; k < s->n_kids; ++k) p = fmax(p, -shape_sdf(s->kids[k], X));
        return p;
    }
    }
    return HUGE_VAL;
}

static void to_local(const Shape *s, const double x[3], double X[3]);

double shape_sdf(const Shape *s, const double x[3])
{
    if (!s->has_xf) return sdf_local(s, x);
    double X[3];
    to_local(s, x, X);
    return s->s * sdf_local(s, X);
}

/* X = pivot + Rot^T (x - pivot - t) / s */
static void to_local(const Shape *s, const double x[3], double X[3])
{
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = (x[k] - s->pivot[k] - s->t[k]) / s->s;
    if (s->has_rot) {
        const double *R = s->rot;
        double e0 = R[0] * d[0] + R[3] * d[1] + R[6] * d[2];
        double e1 = R[1] * d[0] + R[4] * d[1] + R[7] * d[2];
        double e2 = R[2] * d[0] + R[5] * d[1] + R[8] * d[2];
        d[0] = e0, d[1] = e1, d[2] = e2;
    }
    for (int k = 0; k < 3; ++k) X[k] = s->pivot[k] + d[k];
}

int shape_contains(const Shape *s, const double x[3])
{
    for (int k = 0; k < 3; ++k)
        if (x[k] < s->lo[k] || x[k] > s->hi[k]) return 0;
    double X[3];
    if (s->has_xf)
        to_local(s, x, X);
    else
        memcpy(X, x, sizeof X);
    switch (s->type) {
    case SH_MESH:
#if MPM_HAVE_MESH
        return mesh_contains(s->mesh, X);
#else
        return 0;
#endif
    case SH_UNION:
        if (s->kid_tree) return box_tree_any(s->kid_tree, X, kid_contains, s);
        for (int k = 0; k < s->n_kids; ++k)
            if (shape_contains(s->kids[k], X)) return 1;
        return 0;
    case SH_INTERSECTION:
        for (int k = 0; k < s->n_kids; ++k)
            if (!shape_contains(s->kids[k], X)) return 0;
        return 1;
    case SH_DIFFERENCE:
        if (!shape_contains(s->kids[0], X)) return 0;
        for (int k = 1; k < s->n_kids; ++k)
            if (shape_contains(s->kids[k], X)) return 0;
        return 1;
    default: return sdf_local(s, X) <= 0.0;
    }
}

/* ======================================================================
 * Bounds and volume
 * ====================================================================== */

static void bounds_local(const Shape *s, double lo[3], double hi[3])
{
    switch (s->type) {
    case SH_BOX:
    case SH_ELLIPSOID:
        for (int k = 0; k < 3; ++k) lo[k] = s->c[k] - s->h[k], hi[k] = s->c[k] + s->h[k];
        return;
    case SH_SPHERE:
        for (int k = 0; k < 3; ++k) lo[k] = s->c[k] - s->r, hi[k] = s->c[k] + s->r;
        return;
    case SH_CYLINDER:
        /* Along world axis e: the axis segment contributes |a.e| H/2, the
         * end disks r sqrt(1 - (a.e)^2). */
        for (int k = 0; k < 3; ++k) {
            double ae = fabs(s->axis[k]);
            double ext = ae * s->half_h + s->r * sqrt(fmax(0.0, 1.0 - ae * ae));
            lo[k] = s->c[k] - ext, hi[k] = s->c[k] + ext;
        }
        return;
    case SH_TORUS:
        for (int k = 0; k < 3; ++k) {
            double ae = fabs(s->axis[k]);
            double ext = s->R * sqrt(fmax(0.0, 1.0 - ae * ae)) + s->r;
            lo[k] = s->c[k] - ext, hi[k] = s->c[k] + ext;
        }
        return;
    case SH_CAPSULE:
        for (int k = 0; k < 3; ++k)
            lo[k] = fmin(s->a[k], s->b[k]) - s->r, hi[k] = fmax(s->a[k], s->b[k]) + s->r;
        return;
    case SH_HALF_SPACE: {
        for (int k = 0; k < 3; ++k) lo[k] = -HUGE_VAL, hi[k] = HUGE_VAL;
        int nz = 0, kk = 0;
        for (int k = 0; k < 3; ++k)
            if (s->axis[k] != 0.0) ++nz, kk = k;
        if (nz == 1) {
            if (s->axis[kk] > 0)
                hi[kk] = s->c[kk];
            else
                lo[kk] = s->c[kk];
        }
        return;
    }
    case SH_MESH:
#if MPM_HAVE_MESH
        mesh_bounds(s->mesh, lo, hi);
#else
        for (int k = 0; k < 3; ++k) lo[k] = hi[k] = 0.0;
#endif
        return;
    case SH_UNION:
        for (int k = 0; k < 3; ++k) lo[k] = HUGE_VAL, hi[k] = -HUGE_VAL;
        for (int i = 0; i < s->n_kids; ++i)
            for (int k = 0; k < 3; ++k)
                lo[k] = fmin(lo[k], s->kids[i]->lo[k]), hi[k] = fmax(hi[k], s->kids[i]->hi[k]);
        return;
    case SH_INTERSECTION:
        for (int k = 0; k < 3; ++k) lo[k] = -HUGE_VAL, hi[k] = HUGE_VAL;
        for (int i = 0; i < s->n_kids; ++i)
            for (int k = 0; k < 3; ++k)
                lo[k] = fmax(lo[k], s->kids[i]->lo[k]), hi[k] = fmin(hi[k], s->kids[i]->hi[k]);
        return;
    case SH_DIFFERENCE:
        memcpy(lo, s->kids[0]->lo, 3 * sizeof(double));
        memcpy(hi, s->kids[0]->hi, 3 * sizeof(double));
        return;
    }
}

static void compute_world_bounds(Shape *s)
{
    double lo[3], hi[3];
    bounds_local(s, lo, hi);
    if (!s->has_xf) {
        memcpy(s->lo, lo, sizeof lo);
        memcpy(s->hi, hi, sizeof hi);
        return;
    }
    int finite = 1;
    for (int k = 0; k < 3; ++k) finite &= isfinite(lo[k]) && isfinite(hi[k]);
    if (!finite && s->has_rot) {
        /* A rotated unbounded region: give up on tightness. */
        for (int k = 0; k < 3; ++k) s->lo[k] = -HUGE_VAL, s->hi[k] = HUGE_VAL;
        return;
    }
    if (!s->has_rot) {
        for (int k = 0; k < 3; ++k) {
            s->lo[k] = s->pivot[k] + s->t[k] + s->s * (lo[k] - s->pivot[k]);
            s->hi[k] = s->pivot[k] + s->t[k] + s->s * (hi[k] - s->pivot[k]);
        }
        return;
    }
    for (int k = 0; k < 3; ++k) s->lo[k] = HUGE_VAL, s->hi[k] = -HUGE_VAL;
    for (int corner = 0; corner < 8; ++corner) {
        double X[3], d[3], w[3];
        for (int k = 0; k < 3; ++k) X[k] = (corner >> k) & 1 ? hi[k] : lo[k];
        for (int k = 0; k < 3; ++k) d[k] = X[k] - s->pivot[k];
        m3_mulv(s->rot, d, w);
        for (int k = 0; k < 3; ++k) {
            double x = s->pivot[k] + s->t[k] + s->s * w[k];
            s->lo[k] = fmin(s->lo[k], x);
            s->hi[k] = fmax(s->hi[k], x);
        }
    }
}

void shape_bounds(const Shape *s, double lo[3], double hi[3])
{
    memcpy(lo, s->lo, 3 * sizeof(double));
    memcpy(hi, s->hi, 3 * sizeof(double));
}

void shape_reference_bounds(const Shape *s, double lo[3], double hi[3])
{
    if (s->type == SH_CYLINDER && !s->has_xf) {
        double ext = sqrt(s->r * s->r + s->half_h * s->half_h);
        for (int k = 0; k < 3; ++k) lo[k] = s->c[k] - ext, hi[k] = s->c[k] + ext;
        return;
    }
    shape_bounds(s, lo, hi);
}

int shape_is_bounded(const Shape *s)
{
    for (int k = 0; k < 3; ++k)
        if (!isfinite(s->lo[k]) || !isfinite(s->hi[k])) return 0;
    return 1;
}

/* Adaptive octree volume estimate for CSG. A cell whose centre value
 * satisfies |phi| >= half diagonal is entirely outside or inside (valid
 * because |phi| never exceeds the true distance, see shape.h). Cells
 * straddling the surface are split down to a leaf size of (longest bounds
 * extent) / 2^(ROOT_LOG + DEPTH), where the inside fraction of the leaf is
 * taken as clamp(1/2 - phi / edge, 0, 1), exact for a surface plane parallel
 * to a cell face through the leaf. With 256 leaves along the longest side
 * the error on spheres, tori and boxes is below 0.1% (tests/scene/test_shape.c). */
enum { VOL_ROOT = 8, VOL_DEPTH = 5 };

static double vol_rec(const Shape *s, const double c[3], double half, int depth)
{
    double phi = shape_sdf(s, c);
    double hd = half * 1.7320508075688772;
    double cell = 8.0 * half * half * half;
    if (phi >= hd) return 0.0;
    if (phi <= -hd) return cell;
    if (depth == 0) {
        double f = 0.5 - phi / (2.0 * half);
        return cell * (f < 0 ? 0 : (f > 1 ? 1 : f));
    }
    double sum = 0.0, q = 0.5 * half;
    for (int o = 0; o < 8; ++o) {
        double cc[3] = {c[0] + ((o & 1) ? q : -q), c[1] + ((o & 2) ? q : -q), c[2] + ((o & 4) ? q : -q)};
        sum += vol_rec(s, cc, q, depth - 1);
    }
    return sum;
}

static double volume_numeric(const Shape *s)
{
    if (!shape_is_bounded(s)) return HUGE_VAL;
    double ext[3], L = 0.0;
    for (int k = 0; k < 3; ++k) {
        ext[k] = s->hi[k] - s->lo[k];
        if (ext[k] <= 0) return 0.0;
        L = fmax(L, ext[k]);
    }
    double e = L / VOL_ROOT;
    int n[3];
    for (int k = 0; k < 3; ++k) {
        n[k] = (int)ceil(ext[k] / e - 1e-9);
        if (n[k] < 1) n[k] = 1;
    }
    int total = n[0] * n[1] * n[2];
    double *part = malloc(sizeof(double) * (size_t)total);
    if (!part) return NAN;
#pragma omp parallel for schedule(dynamic, 1)
    for (int id = 0; id < total; ++id) {
        int i = id % n[0], j = (id / n[0]) % n[1], k = id / (n[0] * n[1]);
        double c[3] = {s->lo[0] + (i + 0.5) * e, s->lo[1] + (j + 0.5) * e, s->lo[2] + (k + 0.5) * e};
        part[id] = vol_rec(s, c, 0.5 * e, VOL_DEPTH);
    }
    double sum = 0.0; /* serial sum: deterministic for any thread count */
    for (int id = 0; id < total; ++id) sum += part[id];
    free(part);
    return sum;
}

double shape_volume(const Shape *s)
{
    double v, sc = s->has_xf ? s->s * s->s * s->s : 1.0;
    switch (s->type) {
    case SH_BOX: v = 8.0 * s->h[0] * s->h[1] * s->h[2]; break;
    case SH_SPHERE: v = 4.0 / 3.0 * M_PI * s->r * s->r * s->r; break;
    case SH_CYLINDER: v = M_PI * s->r * s->r * 2.0 * s->half_h; break;
    case SH_TORUS: v = 2.0 * M_PI * M_PI * s->R * s->r * s->r; break; /* Pappus */
    case SH_ELLIPSOID: v = 4.0 / 3.0 * M_PI * s->h[0] * s->h[1] * s->h[2]; break;
    case SH_CAPSULE: {
        double ba[3] = {s->b[0] - s->a[0], s->b[1] - s->a[1], s->b[2] - s->a[2]};
        v = M_PI * s->r * s->r * (v3_norm(ba) + 4.0 / 3.0 * s->r);
        break;
    }
    case SH_HALF_SPACE: return HUGE_VAL;
    case SH_MESH:
#if MPM_HAVE_MESH
        v = mesh_volume(s->mesh);
#else
        v = 0.0;
#endif
        break;
    default: return volume_numeric(s); /* CSG, in world space already */
    }
    return v * sc;
}

double shape_volume_bound(const Shape *s)
{
    if (!shape_is_bounded(s)) return HUGE_VAL;
    double box = (s->hi[0] - s->lo[0]) * (s->hi[1] - s->lo[1]) * (s->hi[2] - s->lo[2]);
    double sc = s->has_xf ? s->s * s->s * s->s : 1.0, v = 0.0;
    switch (s->type) {
    case SH_UNION:
        for (int k = 0; k < s->n_kids; ++k) v += shape_volume_bound(s->kids[k]);
        v *= sc;
        break;
    case SH_INTERSECTION:
        v = HUGE_VAL;
        for (int k = 0; k < s->n_kids; ++k) v = fmin(v, shape_volume_bound(s->kids[k]));
        v *= sc;
        break;
    case SH_DIFFERENCE: v = sc * shape_volume_bound(s->kids[0]); break;
    default: v = shape_volume(s); break; /* exact and cheap for primitives and meshes */
    }
    return fmin(v, box);
}

const char *shape_type_name(const Shape *s) { return k_type_names[s->type]; }

int shape_mesh_vertices(const Shape *s, double **xyz, size_t *n)
{
    *xyz = NULL;
    *n = 0;
    if (s->type != SH_MESH || !s->mesh)
        return mpm_error(MPM_EINPUT, "expected a mesh shape, got a %s", k_type_names[s->type]);
#if MPM_HAVE_MESH
    size_t nv = (size_t)mesh_vertex_count(s->mesh);
    const double *v = mesh_vertices(s->mesh);
    double *out = malloc(sizeof(double) * 3 * (nv ? nv : 1));
    if (!out) return mpm_error(MPM_EINTERNAL, "out of memory copying mesh vertices");
    for (size_t k = 0; k < nv; ++k) {
        /* x = pivot + t + s Rot (X - pivot) */
        double d[3], e[3];
        for (int c = 0; c < 3; ++c) d[c] = v[3 * k + c] - s->pivot[c];
        if (s->has_rot)
            m3_mulv(s->rot, d, e);
        else
            memcpy(e, d, sizeof e);
        for (int c = 0; c < 3; ++c) out[3 * k + c] = s->has_xf ? s->pivot[c] + s->t[c] + s->s * e[c] : v[3 * k + c];
    }
    *xyz = out;
    *n = nv;
    return MPM_OK;
#else
    return mpm_error(MPM_EINPUT, "mesh shapes not available in this build");
#endif
}

void shape_free(Shape *s)
{
    if (!s) return;
    for (int k = 0; k < s->n_kids; ++k) shape_free(s->kids[k]);
    free(s->kids);
    box_tree_free(s->kid_tree);
#if MPM_HAVE_MESH
    if (s->mesh) mesh_free(s->mesh);
#endif
    free(s);
}

/* The shape as a core level set (core/level_set.h). */
static const char *ls_type_name(const void *s) { return shape_type_name(s); }
static double ls_sdf(const void *s, const double x[3]) { return shape_sdf(s, x); }
static int ls_contains(const void *s, const double x[3]) { return shape_contains(s, x); }
static void ls_bounds(const void *s, double lo[3], double hi[3]) { shape_bounds(s, lo, hi); }
static void ls_reference_bounds(const void *s, double lo[3], double hi[3]) { shape_reference_bounds(s, lo, hi); }
static void ls_destroy(void *s) { shape_free(s); }

static const LevelSetOps shape_level_set_ops = {ls_type_name, ls_sdf, ls_contains, ls_bounds,
                                                ls_reference_bounds, ls_destroy};

LevelSet shape_level_set(Shape *s)
{
    LevelSet l = {s ? &shape_level_set_ops : NULL, s};
    return l;
}

/* ======================================================================
 * Parsing
 * ====================================================================== */

#define COMMON_KEYS "type", "translate", "rotate_deg", "scale", "pivot"

static int parse_axis(json_t *j, const char *key, const char *file, const char *path, double axis[3])
{
    json_t *v = json_object_get(j, key);
    axis[0] = 0, axis[1] = 1, axis[2] = 0;
    if (!v) return MPM_OK;
    static const char *expected = "expected \"x\", \"y\", \"z\" or a nonzero 3-vector";
    if (json_is_string(v)) {
        const char *a = json_string_value(v);
        if (strcmp(a, "x") == 0)
            axis[0] = 1, axis[1] = 0;
        else if (strcmp(a, "y") == 0)
            ;
        else if (strcmp(a, "z") == 0)
            axis[1] = 0, axis[2] = 1;
        else
            return sj_bad(file, path, key, expected, v);
        return MPM_OK;
    }
    char p[512];
    sj_path(p, sizeof p, path, key);
    if (!json_is_array(v)) return sj_bad(file, path, key, expected, v);
    double a[3];
    int st = sj_value_vec3(v, file, p, a);
    if (st) return st;
    double n = v3_norm(a);
    if (!(n > 0) || !isfinite(n)) return sj_bad(file, path, key, expected, v);
    for (int k = 0; k < 3; ++k) axis[k] = a[k] / n;
    return MPM_OK;
}

/* A union of at least this many shapes answers point queries through a
 * box tree over its kids (core/scene/box_tree.h): O(log n) instead of O(n), which
 * made a union of 20,000 boxes take minutes to sample. Smaller unions keep
 * the plain loop (the tree may skip a kid whose SDF underestimates its
 * distance, so the union's SDF away from it can differ; the sign never). */
enum { UNION_TREE_MIN_KIDS = 32 };

static int build_kid_tree(Shape *s)
{
    double *lo = malloc(sizeof(double) * 3 * (size_t)s->n_kids), *hi = malloc(sizeof(double) * 3 * (size_t)s->n_kids);
    if (lo && hi)
        for (int k = 0; k < s->n_kids; ++k) {
            memcpy(lo + 3 * k, s->kids[k]->lo, 3 * sizeof(double));
            memcpy(hi + 3 * k, s->kids[k]->hi, 3 * sizeof(double));
        }
    s->kid_tree = lo && hi ? box_tree_build(s->n_kids, lo, hi) : NULL;
    free(lo);
    free(hi);
    return s->kid_tree ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory indexing a union of %d shapes", s->n_kids);
}

static int parse_kids(json_t *j, const char *file, const char *path, const char *asset_dir, double dx,
                      Shape *s)
{
    json_t *arr = json_object_get(j, "shapes");
    if (!arr) return sj_missing(file, path, "shapes");
    if (!json_is_array(arr) || json_array_size(arr) == 0)
        return sj_bad(file, path, "shapes", "expected a non-empty array of shapes", arr);
    size_t n = json_array_size(arr);
    if (s->type == SH_DIFFERENCE && n < 2)
        return sj_bad(file, path, "shapes", "expected at least 2 shapes (first minus the others)", arr);
    s->kids = calloc(n, sizeof(Shape *));
    if (!s->kids) return mpm_error(MPM_EINTERNAL, "out of memory parsing shapes");
    char base[512], p[512];
    sj_path(base, sizeof base, path, "shapes");
    for (size_t k = 0; k < n; ++k) {
        sj_path_index(p, sizeof p, base, k);
        int st = shape_parse(json_array_get(arr, k), file, p, asset_dir, dx, &s->kids[k]);
        if (st) return st;
        s->n_kids = (int)k + 1;
    }
    return MPM_OK;
}

static int parse_mesh(json_t *j, const char *file, const char *path, const char *asset_dir, Shape *s)
{
    const char *fname = NULL;
    int st = sj_string(j, "file", 1, file, path, &fname, NULL);
    if (st) return st;
    double mbe = 0.0;
    int have_mbe = 0;
    if ((st = sj_number(j, "max_boundary_edges", 0, file, path, &mbe, &have_mbe))) return st;
    if (have_mbe && !(mbe >= 0 && mbe == floor(mbe) && mbe < 1e9))
        return sj_bad_number(file, path, "max_boundary_edges", "expected a non-negative integer", mbe);
#if MPM_HAVE_MESH
    char full[2048];
    if (fname[0] == '/' || !asset_dir || !asset_dir[0])
        snprintf(full, sizeof full, "%s", fname);
    else
        snprintf(full, sizeof full, "%s/%s", asset_dir, fname);
    FILE *probe = fopen(full, "rb");
    if (!probe) {
        char p[512];
        sj_path(p, sizeof p, path, "file");
        if (fname[0] == '/' || !asset_dir || !asset_dir[0])
            return mpm_error(MPM_EINPUT, "%s: %s: mesh file %s not found", file, p, full);
        return mpm_error(MPM_EINPUT,
                         "%s: %s: mesh file \"%s\" not found in the asset directory %s (looked for %s; pass "
                         "--asset-dir DIR with the directory that holds it)",
                         file, p, fname, asset_dir, full);
    }
    fclose(probe);
    if (have_mbe && mbe > 0)
        st = mesh_load_obj_lenient(full, (int)mbe, &s->mesh);
    else
        st = mesh_load_obj(full, &s->mesh);
    if (st) { /* the loader's message, prefixed with the place in the scene */
        char p[512];
        sj_path(p, sizeof p, path, "file");
        return mpm_error_context(st, "%s: %s", file, p);
    }
    return MPM_OK;
#else
    (void)asset_dir;
    (void)s;
    char p[512];
    sj_path(p, sizeof p, path, "type");
    return mpm_error(MPM_EINPUT, "%s: %s: mesh shapes not available in this build", file, p);
#endif
}

static int parse_body(json_t *j, const char *file, const char *path, const char *asset_dir, double dx,
                      Shape *s)
{
    int st;
    switch (s->type) {
    case SH_BOX: {
        static const char *const keys[] = {COMMON_KEYS, "min", "max", NULL};
        if ((st = sj_check_object(j, file, path, keys))) return st;
        double lo[3], hi[3];
        if ((st = sj_vec3(j, "min", 1, file, path, lo, NULL))) return st;
        if ((st = sj_vec3(j, "max", 1, file, path, hi, NULL))) return st;
        for (int k = 0; k < 3; ++k)
            if (!(hi[k] > lo[k]))
                return sj_bad(file, path, "max", "expected max > min on every axis",
                              json_object_get(j, "max"));
        for (int k = 0; k < 3; ++k) s->c[k] = 0.5 * (lo[k] + hi[k]), s->h[k] = 0.5 * (hi[k] - lo[k]);
        memcpy(s->pivot, s->c, sizeof s->c);
        return MPM_OK;
    }
    case SH_SPHERE: {
        static const char *const keys[] = {COMMON_KEYS, "center", "radius", NULL};
        if ((st = sj_check_object(j, file, path, keys))) return st;
        if ((st = sj_vec3(j, "center", 1, file, path, s->c, NULL))) return st;
        if ((st = sj_positive(j, "radius", 1, file, path, &s->r, NULL))) return st;
        memcpy(s->pivot, s->c, sizeof s->c);
        return MPM_OK;
    }
    case SH_CYLINDER: {
        static const char *const keys[] = {COMMON_KEYS, "center", "radius", "height", "axis", NULL};
        if ((st = sj_check_object(j, file, path, keys))) return st;
        double H = 0;
        if ((st = sj_vec3(j, "center", 1, file, path, s->c, NULL))) return st;
        if ((st = sj_positive(j, "radius", 1, file, path, &s->r, NULL))) return st;
        if ((st = sj_positive(j, "height", 1, file, path, &H, NULL))) return st;
        if ((st = parse_axis(j, "axis", file, path, s->axis))) return st;
        s->half_h = 0.5 * H;
        memcpy(s->pivot, s->c, sizeof s->c);
        return MPM_OK;
    }
    case SH_TORUS: {
        static const char *const keys[] = {COMMON_KEYS, "center", "major_radius", "minor_radius", "axis",
                                           NULL};
        if ((st = sj_check_object(j, file, path, keys))) return st;
        if ((st = sj_vec3(j, "center", 1, file, path, s->c, NULL))) return st;
        if ((st = sj_positive(j, "major_radius", 1, file, path, &s->R, NULL))) return st;
        if ((st = sj_positive(j, "minor_radius", 1, file, path, &s->r, NULL))) return st;
        if (!(s->r < s->R))
            return sj_bad_number(file, path, "minor_radius", "expected a number below major_radius", s->r);
        if ((st = parse_axis(j, "axis", file, path, s->axis))) return st;
        memcpy(s->pivot, s->c, sizeof s->c);
        return MPM_OK;
    }
    case SH_ELLIPSOID: {
        static const char *const keys[] = {COMMON_KEYS, "center", "radii", NULL};
        if ((st = sj_check_object(j, file, path, keys))) return st;
        if ((st = sj_vec3(j, "center", 1, file, path, s->c, NULL))) return st;
        if ((st = sj_vec3(j, "radii", 1, file, path, s->h, NULL))) return st;
        for (int k = 0; k < 3; ++k)
            if (!(s->h[k] > 0))
                return sj_bad(file, path, "radii", "expected three positive numbers",
                              json_object_get(j, "radii"));
        memcpy(s->pivot, s->c, sizeof s->c);
        return MPM_OK;
    }
    case SH_CAPSULE: {
        static const char *const keys[] = {COMMON_KEYS, "a", "b", "radius", NULL};
        if ((st = sj_check_object(j, file, path, keys))) return st;
        if ((st = sj_vec3(j, "a", 1, file, path, s->a, NULL))) return st;
        if ((st = sj_vec3(j, "b", 1, file, path, s->b, NULL))) return st;
        if ((st = sj_positive(j, "radius", 1, file, path, &s->r, NULL))) return st;
        for (int k = 0; k < 3; ++k) s->pivot[k] = 0.5 * (s->a[k] + s->b[k]);
        return MPM_OK;
    }
    case SH_HALF_SPACE: {
        static const char *const keys[] = {COMMON_KEYS, "point", "normal", NULL};
        if ((st = sj_check_object(j, file, path, keys))) return st;
        double n[3];
        if ((st = sj_vec3(j, "point", 1, file, path, s->c, NULL))) return st;
        if ((st = sj_vec3(j, "normal", 1, file, path, n, NULL))) return st;
        double len = v3_norm(n);
        if (!(len > 0) || !isfinite(len))
            return sj_bad(file, path, "normal", "expected a nonzero 3-vector", json_object_get(j, "normal"));
        for (int k = 0; k < 3; ++k) s->axis[k] = n[k] / len;
        memcpy(s->pivot, s->c, sizeof s->c);
        return MPM_OK;
    }
    case SH_MESH: {
        static const char *const keys[] = {COMMON_KEYS, "file", "max_boundary_edges", NULL};
        if ((st = sj_check_object(j, file, path, keys))) return st;
        s->pivot[0] = s->pivot[1] = s->pivot[2] = 0.0;
        return parse_mesh(j, file, path, asset_dir, s);
    }
    case SH_UNION:
    case SH_INTERSECTION:
    case SH_DIFFERENCE: {
        static const char *const keys[] = {COMMON_KEYS, "shapes", NULL};
        if ((st = sj_check_object(j, file, path, keys))) return st;
        if ((st = parse_kids(j, file, path, asset_dir, dx, s))) return st;
        if (s->type == SH_UNION && s->n_kids >= UNION_TREE_MIN_KIDS && (st = build_kid_tree(s))) return st;
        /* default pivot: centre of the untransformed bounds */
        double lo[3], hi[3];
        bounds_local(s, lo, hi);
        for (int k = 0; k < 3; ++k)
            s->pivot[k] = (isfinite(lo[k]) && isfinite(hi[k])) ? 0.5 * (lo[k] + hi[k]) : 0.0;
        return MPM_OK;
    }
    }
    return mpm_error(MPM_EINTERNAL, "shape_parse: unhandled type");
}

static int parse_transform(json_t *j, const char *file, const char *path, Shape *s)
{
    int st, have_t = 0, have_r = 0, have_s = 0, have_p = 0;
    double deg[3] = {0, 0, 0};
    s->s = 1.0;
    if ((st = sj_vec3(j, "translate", 0, file, path, s->t, &have_t))) return st;
    if ((st = sj_vec3(j, "rotate_deg", 0, file, path, deg, &have_r))) return st;
    if ((st = sj_positive(j, "scale", 0, file, path, &s->s, &have_s))) return st;
    if ((st = sj_vec3(j, "pivot", 0, file, path, s->pivot, &have_p))) return st;
    m3_identity(s->rot);
    if (have_r && (deg[0] != 0 || deg[1] != 0 || deg[2] != 0)) {
        /* R = Rz Ry Rx: rotate about x first, then y, then z. */
        double Rx[9], Ry[9], Rz[9], T[9];
        double wx[3] = {deg[0] * M_PI / 180.0, 0, 0};
        double wy[3] = {0, deg[1] * M_PI / 180.0, 0};
        double wz[3] = {0, 0, deg[2] * M_PI / 180.0};
        m3_rotation(wx, Rx);
        m3_rotation(wy, Ry);
        m3_rotation(wz, Rz);
        m3_mul(Ry, Rx, T);
        m3_mul(Rz, T, s->rot);
        s->has_rot = 1;
    }
    s->has_xf = s->has_rot || (have_s && s->s != 1.0) ||
                (have_t && (s->t[0] != 0 || s->t[1] != 0 || s->t[2] != 0));
    return MPM_OK;
}

int shape_parse(json_t *j, const char *file, const char *jpath, const char *asset_dir, double dx,
                Shape **out)
{
    *out = NULL;
    if (!json_is_object(j)) return sj_bad(file, jpath, NULL, "expected a shape object", j);
    const char *type = NULL;
    int st = sj_string(j, "type", 1, file, jpath, &type, NULL);
    if (st) return st;
    int ti = -1;
    for (int k = 0; k < (int)(sizeof k_type_names / sizeof *k_type_names); ++k)
        if (strcmp(type, k_type_names[k]) == 0) ti = k;
    if (ti < 0)
        return sj_bad(file, jpath, "type",
                      "expected a shape type (box, sphere, cylinder, torus, ellipsoid, capsule, "
                      "half_space, mesh, union, intersection, difference)",
                      json_object_get(j, "type"));
    Shape *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory parsing a shape");
    s->type = (ShapeType)ti;
    s->s = 1.0;
    m3_identity(s->rot);
    st = parse_body(j, file, jpath, asset_dir, dx, s);
    if (!st) st = parse_transform(j, file, jpath, s);
    if (st) {
        shape_free(s);
        return st;
    }
    compute_world_bounds(s);
    *out = s;
    return MPM_OK;
}
