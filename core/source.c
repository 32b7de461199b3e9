/* Particle sources (format and semantics in source.h). */
#include "core/source.h"

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/mat3.h"

static atomic_ullong g_examined;

unsigned long long source_samples_examined(void) { return atomic_load(&g_examined); }

void source_free(Source *s)
{
    if (!s) return;
    collider_free(&s->pose);
    free(s->X);
    memset(s, 0, sizeof *s);
}

/* The collider JSON shared by the pose and the scene collider: shape, pivot,
 * motion and oscillation of the source, plus the outflow as material
 * velocity. Returns a new reference or NULL (out of memory). */
static json_t *collider_json(json_t *j, const char *name, const double vel[3])
{
    json_t *c = json_object();
    if (!c) return NULL;
    static const char *const copy[] = {"shape", "pivot", "motion", "oscillation", NULL};
    int bad = json_object_set_new(c, "name", json_string(name)) || json_object_set_new(c, "type", json_string("sticky"));
    for (int k = 0; copy[k] && !bad; ++k) {
        json_t *v = json_object_get(j, copy[k]);
        if (v) bad = json_object_set(c, copy[k], v);
    }
    if (!bad)
        bad = json_object_set_new(c, "material_velocity", json_pack("[f, f, f]", vel[0], vel[1], vel[2])) ||
              json_object_set_new(c, "cfl_speed", json_real(v3_norm(vel)));
    if (bad) {
        json_decref(c);
        return NULL;
    }
    return c;
}

/* Fills the rest-frame bounds of the shape with tile samples (see source.h). */
static int make_samples(Source *s, const PoissonTile *tile, double dx)
{
    double lo[3], hi[3];
    shape_bounds(s->pose.shape, lo, hi);
    double sc = sampler_poisson_min_distance(tile, dx, s->ppc), P = poisson_tile_period(tile) * sc;
    long m[3];
    double copies = 1.0;
    for (int d = 0; d < 3; ++d) {
        double ext = hi[d] - lo[d];
        double md = ceil(ext / P - 1e-12);
        if (md < 1) md = 1;
        if (!(md < 1e6)) return mpm_error(MPM_EINPUT, "source shape too large for its particle spacing");
        m[d] = (long)md;
        copies *= md;
        s->wrap[d] = s->velocity[d] != 0.0;
        s->box_lo[d] = lo[d];
        s->period[d] = md * P;
    }
    size_t nt = poisson_tile_count(tile);
    const double *u = poisson_tile_points(tile);
    if (copies * (double)nt > 2e8) return mpm_error(MPM_EINPUT, "source needs %.3g samples: too many", copies * nt);
    /* count, then fill (sequential: deterministic order by copy, then tile index) */
    size_t n = 0, cap = 0;
    double *X = NULL;
    for (int pass = 0; pass < 2; ++pass) {
        if (pass == 1) {
            cap = n;
            X = malloc(sizeof(double) * 3 * (cap ? cap : 1));
            if (!X) return mpm_error(MPM_EINTERNAL, "out of memory sampling a source");
            n = 0;
        }
        for (long ck = 0; ck < m[2]; ++ck)
            for (long cj = 0; cj < m[1]; ++cj)
                for (long ci = 0; ci < m[0]; ++ci) {
                    long c[3] = {ci, cj, ck};
                    for (size_t k = 0; k < nt; ++k) {
                        double x[3];
                        int keep = 1;
                        for (int d = 0; d < 3 && keep; ++d) {
                            x[d] = lo[d] + (double)c[d] * P + u[3 * k + d] * sc;
                            /* moving axes keep the whole periodic box, fixed axes only the bounds */
                            if (!s->wrap[d] && x[d] > hi[d]) keep = 0;
                        }
                        if (!keep) continue;
                        if (pass == 1) memcpy(X + 3 * n, x, sizeof x);
                        ++n;
                    }
                }
    }
    s->X = X;
    s->n = n;
    return MPM_OK;
}

int source_parse(json_t *j, const char *file, const char *jpath, const char *asset_dir, double dx,
                 const Material *mats, int n_mats, const PoissonTile *tile, const char *default_name,
                 Source *out, Collider *collider)
{
    static const char *const keys[] = {"name",  "material", "shape",       "ppc",      "velocity",
                                       "from",  "until",    "pivot",       "motion",   "oscillation",
                                       "collider", "particle_volume", NULL};
    memset(out, 0, sizeof *out);
    memset(collider, 0, sizeof *collider);
    int st = sj_check_object(j, file, jpath, keys);
    if (st) return st;
    Source s;
    memset(&s, 0, sizeof s);
    const char *name = default_name ? default_name : "source";
    if ((st = sj_string(j, "name", 0, file, jpath, &name, NULL))) return st;
    if (strlen(name) == 0 || strlen(name) >= sizeof s.name)
        return sj_bad(file, jpath, "name", "expected a name of 1 to 63 characters", json_object_get(j, "name"));
    memcpy(s.name, name, strlen(name) + 1);
    const char *mname = NULL;
    if ((st = sj_string(j, "material", 1, file, jpath, &mname, NULL))) return st;
    s.mat = -1;
    for (int k = 0; k < n_mats; ++k)
        if (strcmp(mats[k].name, mname) == 0) s.mat = k;
    if (s.mat < 0) {
        char p[512];
        sj_path(p, sizeof p, jpath, "material");
        return mpm_error(MPM_EINPUT, "%s: %s: unknown material \"%s\"", file, p, mname);
    }
    if ((st = sj_positive(j, "ppc", 1, file, jpath, &s.ppc, NULL))) return st;
    if ((st = sj_vec3(j, "velocity", 1, file, jpath, s.velocity, NULL))) return st;
    if (!(v3_norm(s.velocity) > 0))
        return sj_bad(file, jpath, "velocity", "expected a nonzero 3-vector", json_object_get(j, "velocity"));
    s.from = 0.0;
    s.until = HUGE_VAL;
    if ((st = sj_number(j, "from", 0, file, jpath, &s.from, NULL))) return st;
    json_t *u = json_object_get(j, "until");
    if (u && !json_is_null(u)) {
        if ((st = sj_number(j, "until", 1, file, jpath, &s.until, NULL))) return st;
        if (!(s.until > s.from)) {
            char what[96];
            snprintf(what, sizeof what, "expected a time after \"from\" (%.10g s)", s.from);
            return sj_bad_number(file, jpath, "until", what, s.until);
        }
    }
    s.has_collider = 1;
    if ((st = sj_bool(j, "collider", 0, file, jpath, &s.has_collider, NULL))) return st;
    const char *pv = "sampled";
    if ((st = sj_string(j, "particle_volume", 0, file, jpath, &pv, NULL))) return st;
    double dx3 = dx * dx * dx;
    if (strcmp(pv, "sampled") == 0)
        s.vol = dx3 / (SAMPLER_DENSITY * s.ppc);
    else if (strcmp(pv, "nominal") == 0)
        s.vol = dx3 / s.ppc;
    else
        return sj_bad(file, jpath, "particle_volume", "expected \"sampled\" or \"nominal\"",
                      json_object_get(j, "particle_volume"));
    s.mass = mats[s.mat].density * s.vol;
    if (!(s.vol > 0) || !isfinite(s.vol) || !(s.mass > 0) || !isfinite(s.mass))
        return mpm_error(MPM_EINPUT, "%s: %s: particle volume %g and mass %g are not positive and finite", file,
                         jpath, s.vol, s.mass);
    if (!json_object_get(j, "shape")) {
        char p[512];
        sj_path(p, sizeof p, jpath, "shape");
        return mpm_error(MPM_EINPUT, "%s: %s: missing required field", file, p);
    }

    json_t *cj = collider_json(j, s.name, s.velocity);
    if (!cj) return mpm_error(MPM_EINTERNAL, "out of memory parsing a source");
    st = collider_parse_named(cj, file, jpath, asset_dir, dx, s.name, &s.pose);
    if (!st && !shape_is_bounded(s.pose.shape)) {
        char p[512];
        sj_path(p, sizeof p, jpath, "shape");
        st = mpm_error(MPM_EINPUT, "%s: %s: a source's shape must be bounded (got an unbounded %s)", file, p,
                       shape_type_name(s.pose.shape));
    }
    if (!st && s.has_collider) st = collider_parse_named(cj, file, jpath, asset_dir, dx, s.name, collider);
    json_decref(cj);
    if (!st) {
        st = mpm_error_context(make_samples(&s, tile, dx), "%s: %s", file, jpath);
    }
    if (st) {
        source_free(&s);
        collider_free(collider);
        return st;
    }
    *out = s;
    return MPM_OK;
}

int source_active(const Source *s, double t0)
{
    double tol_until = 1e-9 * fmax(1.0, fabs(s->until)), tol_from = 1e-9 * fmax(1.0, fabs(s->from));
    return t0 >= s->from - tol_from && t0 < s->until - tol_until;
}

/* Rest-frame position of sample k at a displacement whose remainder modulo
 * the wrap period is Dm (in [0, period) on wrapped axes, 0 elsewhere); the
 * stored samples lie in [box_lo, box_lo + period) on wrapped axes. */
static inline void displaced(const Source *s, size_t k, const double Dm[3], double X[3])
{
    for (int d = 0; d < 3; ++d) {
        double x = s->X[3 * k + d];
        if (s->wrap[d]) {
            double r = x - s->box_lo[d] + Dm[d];
            if (r >= s->period[d]) r -= s->period[d];
            x = s->box_lo[d] + r;
        }
        X[d] = x;
    }
}

int source_emit(const Source *s, Particles *p, double t0, double dt, size_t *n_emitted)
{
    if (n_emitted) *n_emitted = 0;
    if (!source_active(s, t0) || !(dt > 0)) return MPM_OK;
    atomic_fetch_add(&g_examined, (unsigned long long)s->n);
    /* a sample at its wrapped position X0 at t0 moves to X0 + step at t1 (not
     * wrapped again: leaving the box means leaving the shape) */
    double t1 = t0 + dt, D0[3], step[3];
    for (int d = 0; d < 3; ++d) {
        D0[d] = 0.0;
        if (s->wrap[d]) {
            D0[d] = fmod(s->velocity[d] * (t0 - s->from), s->period[d]);
            if (D0[d] < 0) D0[d] += s->period[d];
            if (D0[d] >= s->period[d]) D0[d] = 0.0;
        }
        step[d] = s->velocity[d] * dt;
    }
    unsigned char *flag = malloc(s->n ? s->n : 1);
    if (!flag) return mpm_error(MPM_EINTERNAL, "out of memory emitting from source %s", s->name);
    const Shape *shape = s->pose.shape;
    size_t count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count)
    for (size_t k = 0; k < s->n; ++k) {
        double X0[3], X1[3];
        displaced(s, k, D0, X0);
        for (int d = 0; d < 3; ++d) X1[d] = X0[d] + step[d];
        flag[k] = shape_contains(shape, X0) && !shape_contains(shape, X1);
        count += flag[k];
    }
    int st = particles_reserve(p, p->n + count);
    if (!st && count) {
        double R[9], b[3], v[3];
        collider_pose(&s->pose, t1, R, b);
        m3_mulv(R, s->velocity, v);
        const double *c = s->pose.pivot0;
        for (size_t k = 0; k < s->n && !st; ++k) {
            if (!flag[k]) continue;
            double X[3], r[3], x[3];
            displaced(s, k, D0, X);
            for (int d = 0; d < 3; ++d) r[d] = X[d] + step[d] - c[d];
            m3_mulv(R, r, x);
            for (int d = 0; d < 3; ++d) x[d] += c[d] + b[d];
            st = particles_push(p, x, v, s->mass, s->vol, s->mat);
        }
    }
    free(flag);
    if (!st && n_emitted) *n_emitted = count;
    return st;
}

int source_emit_all(const Source *src, int n_src, Particles *p, double t0, double dt)
{
    for (int k = 0; k < n_src; ++k) {
        int st = source_emit(&src[k], p, t0, dt, NULL);
        if (st) return st;
    }
    return MPM_OK;
}
