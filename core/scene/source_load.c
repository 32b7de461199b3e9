/* Source JSON reading and rest-frame sampling (see source_load.h). */
#include "core/scene/source_load.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/mat3.h"
#include "core/scene/collider_load.h"
#include "core/scene/json_read.h"
#include "core/scene/scene_keys.h"

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

/* Fills the rest-frame bounds of the shape with tile samples (see core/source.h). */
static int make_samples(Source *s, const PoissonTile *tile, double dx)
{
    double lo[3], hi[3];
    level_set_bounds(&s->pose.shape, lo, hi);
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
    memset(out, 0, sizeof *out);
    memset(collider, 0, sizeof *collider);
    int st = scene_keys_check(j, file, jpath, scene_source_keys, 0);
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
    if (!st && !level_set_is_bounded(&s.pose.shape)) {
        char p[512];
        sj_path(p, sizeof p, jpath, "shape");
        st = mpm_error(MPM_EINPUT, "%s: %s: a source's shape must be bounded (got an unbounded %s)", file, p,
                       level_set_type_name(&s.pose.shape));
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

