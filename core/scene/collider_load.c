/* Collider JSON reading (see collider_load.h). */
#include "core/scene/collider_load.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/scene/json_read.h"
#include "core/scene/scene_keys.h"
#include "core/scene/shape.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int parse_phase(json_t *j, const char *file, const char *path, int is_last, double t_start,
                       ColliderPhase *ph)
{
    static const char *const keys[] = {"until", "velocity", "angular_velocity_deg", "removed", NULL};
    int st = sj_check_object(j, file, path, keys);
    if (st) return st;
    json_t *u = json_object_get(j, "until");
    ph->t_start = t_start;
    ph->t_end = HUGE_VAL;
    if (u && !json_is_null(u)) {
        if ((st = sj_number(j, "until", 1, file, path, &ph->t_end, NULL))) return st;
        if (!(ph->t_end > t_start)) {
            char what[96];
            snprintf(what, sizeof what, "expected a time after the phase start %.10g s", t_start);
            return sj_bad_number(file, path, "until", what, ph->t_end);
        }
    } else if (!is_last) {
        return sj_bad(file, path, "until", "expected a number (only the last phase may omit it)", u);
    }
    double deg[3] = {0, 0, 0};
    if ((st = sj_vec3(j, "velocity", 0, file, path, ph->vel, NULL))) return st;
    if ((st = sj_vec3(j, "angular_velocity_deg", 0, file, path, deg, NULL))) return st;
    for (int k = 0; k < 3; ++k) ph->omega[k] = deg[k] * (M_PI / 180.0);
    if ((st = sj_bool(j, "removed", 0, file, path, &ph->removed, NULL))) return st;
    return MPM_OK;
}

static int parse_oscillation(json_t *j, const char *file, const char *path, Collider *c)
{
    json_t *o = json_object_get(j, "oscillation");
    if (!o) return MPM_OK;
    char p[512];
    sj_path(p, sizeof p, path, "oscillation");
    static const char *const keys[] = {"amplitude", "angular_frequency_deg", "phase_deg", NULL};
    int st = sj_check_object(o, file, p, keys);
    if (st) return st;
    double w[3] = {0, 0, 0}, ph[3] = {0, 0, 0};
    if ((st = sj_vec3(o, "amplitude", 1, file, p, c->osc_amp, NULL))) return st;
    if ((st = sj_vec3(o, "angular_frequency_deg", 1, file, p, w, NULL))) return st;
    if ((st = sj_vec3(o, "phase_deg", 0, file, p, ph, NULL))) return st;
    for (int k = 0; k < 3; ++k) {
        c->osc_omega[k] = w[k] * (M_PI / 180.0);
        c->osc_phase[k] = ph[k] * (M_PI / 180.0);
    }
    c->has_osc = 1;
    return MPM_OK;
}

static int parse_motion(json_t *j, const char *file, const char *path, Collider *c)
{
    json_t *m = json_object_get(j, "motion");
    size_t n = m ? json_array_size(m) : 0;
    if (m && (!json_is_array(m) || n == 0))
        return sj_bad(file, path, "motion", "expected a non-empty array of motion phases", m);
    /* One spare slot for the implicit rest phase after a final "until". */
    c->phases = calloc(n + 1, sizeof *c->phases);
    if (!c->phases) return mpm_error(MPM_EINTERNAL, "out of memory parsing a collider");
    char base[512], p[512];
    sj_path(base, sizeof base, path, "motion");
    double t = 0.0;
    for (size_t k = 0; k < n; ++k) {
        sj_path_index(p, sizeof p, base, k);
        int st = parse_phase(json_array_get(m, k), file, p, k + 1 == n, t, &c->phases[k]);
        if (st) return st;
        t = c->phases[k].t_end;
    }
    c->n_phases = (int)n;
    if (n == 0 || isfinite(t)) {
        ColliderPhase *rest = &c->phases[c->n_phases++];
        rest->t_start = t;
        rest->t_end = HUGE_VAL;
    }
    collider_init_poses(c);
    return MPM_OK;
}

/* "friction": mu >= 0, only on slip colliders. */
static int parse_friction(json_t *j, const char *file, const char *path, Collider *c)
{
    int have = 0;
    int st = sj_number(j, "friction", 0, file, path, &c->friction, &have);
    if (st || !have) return st;
    if (!(c->friction >= 0.0) || !isfinite(c->friction))
        return sj_bad_number(file, path, "friction", "expected a non-negative number", c->friction);
    if (c->friction > 0.0 && c->kind != COLLIDER_SLIP)
        return sj_bad_number(file, path, "friction",
                             "expected 0 on a sticky collider (friction applies to \"type\": \"slip\")",
                             c->friction);
    return MPM_OK;
}

int collider_parse_named(json_t *j, const char *file, const char *jpath, const char *asset_dir, double dx,
                         const char *default_name, Collider *out)
{
    Collider c;
    memset(&c, 0, sizeof c);
    memset(out, 0, sizeof *out);
    int st = scene_keys_check(j, file, jpath, scene_collider_keys, 0);
    if (st) return st;
    const char *name = default_name ? default_name : "collider", *type = "sticky";
    if ((st = sj_string(j, "name", 0, file, jpath, &name, NULL))) return st;
    if (strlen(name) == 0 || strlen(name) >= sizeof c.name)
        return sj_bad(file, jpath, "name", "expected a name of 1 to 63 characters", json_object_get(j, "name"));
    memcpy(c.name, name, strlen(name) + 1);
    if ((st = sj_string(j, "type", 0, file, jpath, &type, NULL))) return st;
    if (strcmp(type, "sticky") == 0)
        c.kind = COLLIDER_STICKY;
    else if (strcmp(type, "slip") == 0)
        c.kind = COLLIDER_SLIP;
    else
        return sj_bad(file, jpath, "type", "expected \"sticky\" or \"slip\"", json_object_get(j, "type"));
    json_t *sh = json_object_get(j, "shape");
    char p[512];
    sj_path(p, sizeof p, jpath, "shape");
    if (!sh) return mpm_error(MPM_EINPUT, "%s: %s: missing required field", file, p);
    Shape *shape = NULL;
    if ((st = shape_parse(sh, file, p, asset_dir, dx, &shape))) return st;
    c.shape = shape_level_set(shape);
    /* pivot: explicit, else the bounds centre (finite axes only) */
    double lo[3], hi[3];
    level_set_bounds(&c.shape, lo, hi);
    for (int k = 0; k < 3; ++k) c.pivot0[k] = (isfinite(lo[k]) && isfinite(hi[k])) ? 0.5 * (lo[k] + hi[k]) : 0.0;
    c.cfl_speed = -1.0;
    int have_cfl = 0;
    if ((st = sj_vec3(j, "pivot", 0, file, jpath, c.pivot0, NULL)) ||
        (st = sj_vec3(j, "material_velocity", 0, file, jpath, c.material_vel, NULL)) ||
        (st = sj_number(j, "cfl_speed", 0, file, jpath, &c.cfl_speed, &have_cfl)) ||
        (st = parse_oscillation(j, file, jpath, &c)) || (st = parse_motion(j, file, jpath, &c))) {
        collider_free(&c);
        return st;
    }
    if (have_cfl && !(c.cfl_speed >= 0)) {
        st = sj_bad_number(file, jpath, "cfl_speed", "expected a non-negative number", c.cfl_speed);
        collider_free(&c);
        return st;
    }
    if ((st = parse_friction(j, file, jpath, &c))) {
        collider_free(&c);
        return st;
    }
    c.fd_h = dx > 0 && isfinite(dx) ? 1e-3 * dx : 1e-6;
    *out = c;
    return MPM_OK;
}

int collider_parse(json_t *j, const char *file, const char *jpath, const char *asset_dir, double dx,
                   Collider *out)
{
    return collider_parse_named(j, file, jpath, asset_dir, dx, NULL, out);
}
