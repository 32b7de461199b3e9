/* Scene loading and validation (format in scene_load.h). */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include "core/scene/scene_load.h"

#include <dirent.h>
#include <errno.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "core/mat3.h"
#include "core/scene/collider_load.h"
#include "core/scene/data_dir.h"
#include "core/scene/json_read.h"
#include "core/scene/noise.h"
#include "core/scene/rng.h"
#include "core/scene/sampler.h"
#include "core/scene/scene_keys.h"
#include "core/scene/shape.h"
#include "core/scene/source_load.h"
#include "core/transfer.h"

const char *scene_dir(void)
{
    static _Thread_local char dir[1000]; /* leaves room for "/NAME.json" in a 1024-byte path */
    data_dir_find("scenes", "MPM_SCENE_DIR", dir, sizeof dir);
    return dir;
}

static int is_builtin_name(const char *s)
{
    size_t n = strlen(s);
    if (strchr(s, '/')) return 0;
    if (n >= 5 && strcmp(s + n - 5, ".json") == 0) return 0;
    return 1;
}

static int file_exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

/* ======================================================================
 * Listing built-ins
 * ====================================================================== */

static int cmp_str(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

/* Sorted built-in names (without .json); caller frees each and the array.
 * Returns -1 without a message when the directory cannot be opened (the
 * callers word it: listing fails, an unknown name says "none"). */
static int list_names(char ***names_out, int *n_out)
{
    *names_out = NULL;
    *n_out = 0;
    DIR *d = opendir(scene_dir());
    if (!d) return -1;
    char **names = NULL;
    int n = 0, cap = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        size_t len = strlen(e->d_name);
        if (len <= 5 || strcmp(e->d_name + len - 5, ".json") != 0 || e->d_name[0] == '.') continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 16;
            char **q = realloc(names, (size_t)cap * sizeof *q);
            if (!q) break;
            names = q;
        }
        names[n] = malloc(len - 4);
        if (!names[n]) break;
        memcpy(names[n], e->d_name, len - 5);
        names[n][len - 5] = '\0';
        ++n;
    }
    closedir(d);
    if (n > 1) qsort(names, (size_t)n, sizeof *names, cmp_str);
    *names_out = names;
    *n_out = n;
    return MPM_OK;
}

static void free_names(char **names, int n)
{
    for (int k = 0; k < n; ++k) free(names[k]);
    free(names);
}

int scene_list(SceneListFn fn, void *ctx)
{
    char **names;
    int n;
    if (list_names(&names, &n))
        return mpm_error(MPM_EINPUT, "cannot open the scene directory %s (set MPM_SCENE_DIR)", scene_dir());
    for (int k = 0; k < n; ++k) {
        char path[2048];
        snprintf(path, sizeof path, "%s/%s.json", scene_dir(), names[k]);
        json_error_t err;
        json_t *root = json_load_file(path, 0, &err);
        const char *desc = "(unreadable scene file)";
        json_t *dj = root ? json_object_get(root, "description") : NULL;
        if (root) desc = json_is_string(dj) ? json_string_value(dj) : "";
        fn(names[k], desc, ctx);
        json_decref(root);
    }
    free_names(names, n);
    return MPM_OK;
}

/* ======================================================================
 * Overrides
 * ====================================================================== */


static int all_digits(const char *s)
{
    if (!*s) return 0;
    for (; *s; ++s)
        if (*s < '0' || *s > '9') return 0;
    return 1;
}

/* What a --set path may name where it failed: the keys the object holds, or
 * the array's index range, for the one-line error. */
static const char *keys_there(const json_t *cur, const SceneKey *may_add, char *buf, size_t n)
{
    if (json_is_array(cur)) {
        size_t len = json_array_size(cur);
        if (len) snprintf(buf, n, " (indices 0..%zu)", len - 1);
        else snprintf(buf, n, " (an empty array)");
        return buf;
    }
    if (!json_is_object(cur)) {
        snprintf(buf, n, " (its parent is a %s, not an object)", json_is_string(cur) ? "string" : "number or literal");
        return buf;
    }
    size_t used = (size_t)snprintf(buf, n, " (there:");
    const char *k;
    json_t *v;
    int first = 1;
    json_object_foreach((json_t *)cur, k, v) {
        if (used >= n) break;
        used += (size_t)snprintf(buf + used, n - used, "%s %s", first ? "" : ",", k);
        first = 0;
    }
    if (first && used < n) used += (size_t)snprintf(buf + used, n - used, " nothing");
    first = 1;
    for (const SceneKey *sk = may_add; sk && sk->name && used < n; ++sk)
        if (sk->optional && !json_object_get(cur, sk->name)) {
            used += (size_t)snprintf(buf + used, n - used, "%s %s", first ? "; may be added:" : ",", sk->name);
            first = 0;
        }
    if (used < n) snprintf(buf + used, n - used, ")");
    if (used >= n && n > 5) strcpy(buf + n - 5, "...)");
    return buf;
}

static int apply_override(json_t *root, const char *file, const SceneOverride *o)
{
    if (!o->key || !o->key[0] || !o->value)
        return mpm_error(MPM_EINPUT, "%s: --set: expected key=value", file);
    char key[512];
    if (strlen(o->key) >= sizeof key) return mpm_error(MPM_EINPUT, "%s: --set %s: key too long", file, o->key);
    strcpy(key, o->key);
    /* split into tokens */
    char *tok[64];
    int nt = 0;
    for (char *p = key;;) {
        if (nt == 64) return mpm_error(MPM_EINPUT, "%s: --set %s: path too deep", file, o->key);
        tok[nt++] = p;
        char *dot = strchr(p, '.');
        if (!dot) break;
        *dot = '\0';
        p = dot + 1;
    }
    for (int k = 0; k < nt; ++k)
        if (!tok[k][0]) return mpm_error(MPM_EINPUT, "%s: --set %s: empty path component", file, o->key);
    json_t *cur = root;
    char path[512] = "";
    for (int k = 0; k + 1 < nt; ++k) {
        json_t *next = NULL;
        if (json_is_object(cur))
            next = json_object_get(cur, tok[k]);
        else if (json_is_array(cur) && all_digits(tok[k]))
            next = json_array_get(cur, (size_t)strtoull(tok[k], NULL, 10));
        char np[512];
        sj_path(np, sizeof np, path, tok[k]);
        char there[400];
        if (!next)
            return mpm_error(MPM_EINPUT, "%s: --set %s: %s does not exist%s", file, o->key, np,
                             keys_there(cur, NULL, there, sizeof there));
        strcpy(path, np);
        cur = next;
    }
    json_error_t err;
    json_t *val = json_loads(o->value, JSON_DECODE_ANY, &err);
    if (!val) val = json_string(o->value);
    if (!val) return mpm_error(MPM_EINPUT, "%s: --set %s: value is not valid UTF-8", file, o->key);
    const char *leaf = tok[nt - 1];
    char lp[512];
    sj_path(lp, sizeof lp, path, leaf);
    if (json_is_object(cur)) {
        if (!json_object_get(cur, leaf)) { /* --set may add a key its object's table lets be absent */
            const SceneKey *keys = NULL;
            if (nt == 1)
                keys = scene_top_keys;
            else if (nt == 3 && strcmp(tok[0], "materials") == 0)
                keys = scene_material_keys;
            else if (nt == 4 && strcmp(tok[0], "materials") == 0 && strcmp(tok[2], "plasticity") == 0)
                keys = scene_plasticity_keys;
            else if (nt == 3 && strcmp(tok[0], "objects") == 0)
                keys = scene_object_keys;
            else if (nt == 3 && strcmp(tok[0], "colliders") == 0)
                keys = scene_collider_keys;
            else if (nt == 3 && strcmp(tok[0], "sources") == 0)
                keys = scene_source_keys;
            if (!keys || !scene_key_optional(keys, leaf)) {
                json_decref(val);
                char there[400];
                return mpm_error(MPM_EINPUT, "%s: --set %s: %s does not exist%s", file, o->key, lp,
                                 keys_there(cur, keys, there, sizeof there));
            }
        }
        json_object_set_new(cur, leaf, val);
        return MPM_OK;
    }
    if (json_is_array(cur) && all_digits(leaf)) {
        size_t idx = (size_t)strtoull(leaf, NULL, 10);
        if (idx < json_array_size(cur)) {
            json_array_set_new(cur, idx, val);
            return MPM_OK;
        }
    }
    json_decref(val);
    char there[400];
    return mpm_error(MPM_EINPUT, "%s: --set %s: %s does not exist%s", file, o->key, lp, keys_there(cur, NULL, there, sizeof there));
}

/* ======================================================================
 * Validation helpers
 * ====================================================================== */

static int read_name(json_t *obj, const char *key, int required, const char *file, const char *path,
                     char *dst, size_t cap)
{
    const char *s = NULL;
    int present = 0;
    int st = sj_string(obj, key, required, file, path, &s, &present);
    if (st || !present) return st;
    if (strlen(s) == 0 || strlen(s) >= cap) {
        char what[64];
        snprintf(what, sizeof what, "expected a string of 1 to %zu characters", cap - 1);
        return sj_bad(file, path, key, what, json_object_get(obj, key));
    }
    memcpy(dst, s, strlen(s) + 1);
    return MPM_OK;
}

static int parse_material(json_t *j, const char *name, const char *file, const char *path, Material *m)
{
    int st = scene_keys_check(j, file, path, scene_material_keys, 0);
    if (st) return st;
    memset(m, 0, sizeof *m);
    if (strlen(name) == 0 || strlen(name) >= sizeof m->name)
        return mpm_error(MPM_EINPUT, "%s: %s: material names must have 1 to 63 characters", file, path);
    memcpy(m->name, name, strlen(name) + 1);
    if ((st = sj_positive(j, "E", 1, file, path, &m->E, NULL))) return st;
    if ((st = sj_number(j, "nu", 1, file, path, &m->nu, NULL))) return st;
    if (!(m->nu > -1.0 && m->nu < 0.5))
        return sj_bad_number(file, path, "nu", "expected a Poisson ratio in (-1, 0.5)", m->nu);
    if ((st = sj_positive(j, "density", 1, file, path, &m->density, NULL))) return st;
    m->plasticity = PLASTICITY_NONE;
    m->min_Jp = 0.0;
    m->max_Jp = 1e30;
    json_t *pj = json_object_get(j, "plasticity");
    if (pj) {
        char pp[512];
        sj_path(pp, sizeof pp, path, "plasticity");
        if ((st = scene_keys_check(pj, file, pp, scene_plasticity_keys, 0))) return st;
        const char *type = NULL;
        if ((st = sj_string(pj, "type", 1, file, pp, &type, NULL))) return st;
        if (strcmp(type, "none") == 0) {
            if ((st = scene_keys_check(pj, file, pp, scene_plasticity_keys, SCENE_PLASTICITY_NONE))) return st;
        } else if (strcmp(type, "von_mises") == 0) {
            if ((st = scene_keys_check(pj, file, pp, scene_plasticity_keys, SCENE_PLASTICITY_VON_MISES))) return st;
            m->plasticity = PLASTICITY_VON_MISES;
            if ((st = sj_positive(pj, "yield_stress", 1, file, pp, &m->yield_stress, NULL))) return st;
        } else if (strcmp(type, "snow") == 0) {
            if ((st = scene_keys_check(pj, file, pp, scene_plasticity_keys, SCENE_PLASTICITY_SNOW))) return st;
            m->plasticity = PLASTICITY_SNOW;
            if ((st = sj_number(pj, "theta_c", 1, file, pp, &m->theta_c, NULL))) return st;
            if (!(m->theta_c > 0 && m->theta_c < 1))
                return sj_bad_number(file, pp, "theta_c", "expected a number in (0, 1)", m->theta_c);
            if ((st = sj_number(pj, "theta_s", 1, file, pp, &m->theta_s, NULL))) return st;
            if (!(m->theta_s >= 0))
                return sj_bad_number(file, pp, "theta_s", "expected a non-negative number", m->theta_s);
            if ((st = sj_number(pj, "hardening", 0, file, pp, &m->hardening, NULL))) return st;
            if (!(m->hardening >= 0))
                return sj_bad_number(file, pp, "hardening", "expected a non-negative number", m->hardening);
            if ((st = sj_number(pj, "min_Jp", 0, file, pp, &m->min_Jp, NULL))) return st;
            if ((st = sj_number(pj, "max_Jp", 0, file, pp, &m->max_Jp, NULL))) return st;
            if (!(m->max_Jp > m->min_Jp))
                return sj_bad_number(file, pp, "max_Jp", "expected a number above min_Jp", m->max_Jp);
        } else {
            return sj_bad(file, pp, "type", "expected \"none\", \"von_mises\" or \"snow\"",
                          json_object_get(pj, "type"));
        }
    }
    material_derive(m);
    if (!isfinite(m->mu) || !isfinite(m->lambda) || !isfinite(m->stiffness)) {
        char p[512];
        sj_path(p, sizeof p, path, "E");
        return mpm_error(MPM_EINPUT, "%s: %s: E = %.10g and nu = %.10g give non-finite Lame parameters", file, p, m->E,
                         m->nu);
    }
    return MPM_OK;
}

typedef struct {
    Shape *shape;
    int mat;
    double ppc;
    SamplingKind sampling;
    double velocity[3];
    int has_F;
    double F_min, F_max;
    uint64_t F_seed;
    int F_per_particle;
    int F_fixed;            /* "type": "diagonal": F = diag(F_values) */
    double F_values[3];
    double F_inverted;      /* "inverted_fraction": share of particles with d0 negated (det F < 0) */
    int has_stiffness_var;  /* "stiffness_variation": some particles get material stiff_mat */
    int stiff_checker;      /* pattern: 1 checkerboard of cells, 0 random per particle */
    double stiff_factor, stiff_cell;
    uint64_t stiff_seed;
    int stiff_mat;
    size_t surf_n;   /* surface particles (after --scale) */
    Shape *surf_mesh; /* "vertices_of": take (a subset of) its vertices; else surface samples */
    int has_variation; /* "variation": clumpy density (and snow pre-compaction) */
    double var_amplitude, var_length;
    uint64_t var_seed;
    double volume;    /* shape_volume once computed (the budget check may need it), else 0 */
} ObjectSpec;

/* Optional "seed": a non-negative integer, else `default_seed`. */
static int parse_seed(json_t *j, const char *file, const char *path, uint64_t default_seed, uint64_t *out)
{
    *out = default_seed;
    json_t *sj = json_object_get(j, "seed");
    if (!sj) return MPM_OK;
    if (!json_is_integer(sj) || json_integer_value(sj) < 0)
        return sj_bad(file, path, "seed", "expected a non-negative integer", sj);
    *out = (uint64_t)json_integer_value(sj);
    return MPM_OK;
}

/* "variation": {"amplitude": a in [0, 1), "length": L > 0, "seed": s}. */
static int parse_variation(json_t *j, const char *file, const char *path, uint64_t default_seed, ObjectSpec *o)
{
    static const char *const keys[] = {"amplitude", "length", "seed", NULL};
    int st = sj_check_object(j, file, path, keys);
    if (st) return st;
    if ((st = sj_number(j, "amplitude", 1, file, path, &o->var_amplitude, NULL))) return st;
    if (!(o->var_amplitude >= 0.0 && o->var_amplitude < 1.0))
        return sj_bad_number(file, path, "amplitude", "expected a number in [0, 1)", o->var_amplitude);
    if ((st = sj_positive(j, "length", 1, file, path, &o->var_length, NULL))) return st;
    if (!isfinite(o->var_length))
        return sj_bad_number(file, path, "length", "expected a positive finite length [m]", o->var_length);
    if ((st = parse_seed(j, file, path, default_seed, &o->var_seed))) return st;
    o->has_variation = 1;
    return MPM_OK;
}

/* Applies each object's "variation" to its particles (after sampling and
 * after the plastic state exists): mass *= 1 + a nu(x); for snow with
 * hardening J_p = 1 / (1 + a nu(x)), the plastic compaction that gives that
 * density. */
static void apply_variations(Scene *sc, const ObjectSpec *objs, int nobj)
{
    Particles *P = &sc->particles;
    for (int i = 0; i < nobj; ++i) {
        const ObjectSpec *o = &objs[i];
        if (!o->has_variation) continue;
        const Material *m = &sc->materials[o->mat];
        int compact = P->Jp && m->plasticity == PLASTICITY_SNOW && m->hardening != 0.0;
        for (size_t k = sc->object_offsets[i]; k < sc->object_offsets[i + 1]; ++k) {
            double ratio = 1.0 + o->var_amplitude * value_noise3(o->var_seed, o->var_length, P->x + 3 * k);
            P->mass[k] *= ratio;
            if (compact) P->Jp[k] = 1.0 / ratio;
        }
    }
}

/* "surface_particles": {"count": N} | {"vertices_of": mesh shape}. */
static int parse_surface(json_t *j, const char *file, const char *path, const char *asset_dir, double dx,
                         double scale, ObjectSpec *o)
{
    static const char *const keys[] = {"count", "vertices_of", NULL};
    int st = sj_check_object(j, file, path, keys);
    if (st) return st;
    json_t *cnt = json_object_get(j, "count"), *vo = json_object_get(j, "vertices_of");
    if ((cnt != NULL) == (vo != NULL))
        return mpm_error(MPM_EINPUT, "%s: %s: expected exactly one of \"count\" and \"vertices_of\"", file, path);
    double n = 0;
    if (cnt) {
        if ((st = sj_number(j, "count", 1, file, path, &n, NULL))) return st;
        if (!(n >= 0 && n == floor(n) && n < 1e9))
            return sj_bad_number(file, path, "count", "expected a non-negative integer", n);
    } else {
        char vp[512];
        sj_path(vp, sizeof vp, path, "vertices_of");
        if ((st = shape_parse(vo, file, vp, asset_dir, dx, &o->surf_mesh))) return st;
        if (strcmp(shape_type_name(o->surf_mesh), "mesh") != 0)
            return mpm_error(MPM_EINPUT, "%s: %s: expected a mesh shape, got a %s", file, vp,
                             shape_type_name(o->surf_mesh));
        double *v = NULL;
        size_t nv = 0;
        if ((st = shape_mesh_vertices(o->surf_mesh, &v, &nv))) return st;
        free(v);
        n = (double)nv;
    }
    /* the count is for scale 1; a coarser grid keeps the same share of particles */
    o->surf_n = (size_t)llround(n / (scale * scale * scale));
    return MPM_OK;
}

/* "initial_F": {"type": "random_diagonal", "min", "max", "seed", "per_particle"}
 * or {"type": "diagonal", "values": [d0, d1, d2]}, either with
 * "inverted_fraction". */
static int parse_initial_F(json_t *j, const char *file, const char *path, uint64_t default_seed,
                           ObjectSpec *o)
{
    static const char *const keys[] = {"type", "min", "max", "seed", "per_particle", "values", "inverted_fraction",
                                       NULL};
    static const char *const fixed_keys[] = {"type", "values", "seed", "inverted_fraction", NULL};
    int st = sj_check_object(j, file, path, keys);
    if (st) return st;
    const char *type = NULL;
    if ((st = sj_string(j, "type", 1, file, path, &type, NULL))) return st;
    if (strcmp(type, "diagonal") == 0) {
        if ((st = sj_check_object(j, file, path, fixed_keys))) return st;
        if ((st = sj_vec3(j, "values", 1, file, path, o->F_values, NULL))) return st;
        for (int d = 0; d < 3; ++d)
            if (!(o->F_values[d] != 0.0) || !isfinite(o->F_values[d]))
                return sj_bad(file, path, "values", "expected three non-zero finite numbers", json_object_get(j, "values"));
        o->F_fixed = 1;
    } else if (strcmp(type, "random_diagonal") == 0) {
        if (json_object_get(j, "values"))
            return sj_bad(file, path, "values", "expected no \"values\" for \"random_diagonal\" (min, max)",
                          json_object_get(j, "values"));
        if ((st = sj_positive(j, "min", 1, file, path, &o->F_min, NULL))) return st;
        if ((st = sj_number(j, "max", 1, file, path, &o->F_max, NULL))) return st;
        if (!(o->F_max >= o->F_min)) return sj_bad_number(file, path, "max", "expected a number >= min", o->F_max);
        o->F_per_particle = 1;
        if ((st = sj_bool(j, "per_particle", 0, file, path, &o->F_per_particle, NULL))) return st;
    } else {
        return sj_bad(file, path, "type", "expected \"random_diagonal\" or \"diagonal\"", json_object_get(j, "type"));
    }
    if ((st = parse_seed(j, file, path, default_seed, &o->F_seed))) return st;
    o->F_inverted = 0.0;
    if ((st = sj_number(j, "inverted_fraction", 0, file, path, &o->F_inverted, NULL))) return st;
    if (!(o->F_inverted >= 0.0 && o->F_inverted <= 1.0))
        return sj_bad_number(file, path, "inverted_fraction", "expected a fraction in [0, 1]", o->F_inverted);
    o->has_F = 1;
    return MPM_OK;
}

/* The object's initial F of particle k (diag, in order): the fixed or random
 * diagonal, then d0 negated for the inverted share. `rng` and `flip` are
 * seeded from F_seed by the caller. */
static void initial_F_diagonal(const ObjectSpec *o, size_t k, Rng *rng, Rng *flip, double diag[3])
{
    if (o->F_fixed) {
        for (int d = 0; d < 3; ++d) diag[d] = o->F_values[d];
    } else if (o->F_per_particle || k == 0) {
        for (int d = 0; d < 3; ++d) diag[d] = rng_uniform(rng, o->F_min, o->F_max);
    }
    if (o->F_inverted > 0.0 && rng_uniform(flip, 0.0, 1.0) < o->F_inverted) diag[0] = -fabs(diag[0]);
    else if (!o->F_fixed) diag[0] = fabs(diag[0]);
}

/* "stiffness_variation": {"pattern": "checkerboard" | "random", "factor": f,
 * "cell": L (checkerboard), "seed" (random)}. */
static int parse_stiffness_variation(json_t *j, const char *file, const char *path, double dx, uint64_t default_seed,
                                     ObjectSpec *o)
{
    static const char *const keys[] = {"pattern", "factor", "cell", "seed", NULL};
    int st = sj_check_object(j, file, path, keys);
    if (st) return st;
    const char *pattern = NULL;
    if ((st = sj_string(j, "pattern", 1, file, path, &pattern, NULL))) return st;
    if (strcmp(pattern, "checkerboard") == 0) o->stiff_checker = 1;
    else if (strcmp(pattern, "random") == 0) o->stiff_checker = 0;
    else return sj_bad(file, path, "pattern", "expected \"checkerboard\" or \"random\"", json_object_get(j, "pattern"));
    if ((st = sj_positive(j, "factor", 1, file, path, &o->stiff_factor, NULL))) return st;
    if (!isfinite(o->stiff_factor))
        return sj_bad_number(file, path, "factor", "expected a positive finite number", o->stiff_factor);
    o->stiff_cell = dx;
    if (!o->stiff_checker && json_object_get(j, "cell"))
        return sj_bad(file, path, "cell", "expected no \"cell\" for the random pattern", json_object_get(j, "cell"));
    if ((st = sj_positive(j, "cell", 0, file, path, &o->stiff_cell, NULL))) return st;
    if (!isfinite(o->stiff_cell))
        return sj_bad_number(file, path, "cell", "expected a positive finite length [m]", o->stiff_cell);
    if (o->stiff_checker && json_object_get(j, "seed"))
        return sj_bad(file, path, "seed", "expected no \"seed\" for the checkerboard pattern", json_object_get(j, "seed"));
    if ((st = parse_seed(j, file, path, default_seed, &o->stiff_seed))) return st;
    o->has_stiffness_var = 1;
    return MPM_OK;
}

/* The stiffer (or softer) twin of each varied object's material: a copy with
 * E times the factor, named "NAME*FACTOR", added once per (material, factor)
 * after the scene's materials. */
static int add_stiffness_materials(Scene *sc, const char *file, ObjectSpec *objs, int nobj)
{
    for (int i = 0; i < nobj; ++i) {
        ObjectSpec *o = &objs[i];
        if (!o->has_stiffness_var) continue;
        const Material *base = &sc->materials[o->mat];
        char name[64];
        snprintf(name, sizeof name, "%.40s*%g", base->name, o->stiff_factor);
        o->stiff_mat = -1;
        for (int k = 0; k < sc->n_materials; ++k)
            if (strcmp(sc->materials[k].name, name) == 0) o->stiff_mat = k;
        if (o->stiff_mat >= 0) continue;
        Material *m = realloc(sc->materials, sizeof(Material) * (size_t)(sc->n_materials + 1));
        if (!m) return mpm_error(MPM_EINTERNAL, "out of memory");
        sc->materials = m;
        Material *t = &sc->materials[sc->n_materials];
        *t = sc->materials[o->mat];
        snprintf(t->name, sizeof t->name, "%s", name);
        t->E *= o->stiff_factor;
        material_derive(t);
        if (!isfinite(t->E) || !isfinite(t->mu) || !isfinite(t->lambda) || !isfinite(t->stiffness))
            return mpm_error(MPM_EINPUT,
                             "%s: objects.%d.stiffness_variation.factor: E = %g times %g gives non-finite Lame parameters",
                             file, i, sc->materials[o->mat].E, o->stiff_factor);
        o->stiff_mat = sc->n_materials++;
    }
    return MPM_OK;
}

/* Assigns the twin material to the checkerboard's odd cells (floor(x / cell)
 * summed over the axes) or to a random half of the particles. */
static void apply_stiffness_variations(Scene *sc, const ObjectSpec *objs, int nobj)
{
    Particles *P = &sc->particles;
    for (int i = 0; i < nobj; ++i) {
        const ObjectSpec *o = &objs[i];
        if (!o->has_stiffness_var) continue;
        Rng rng;
        rng_seed(&rng, o->stiff_seed);
        for (size_t k = sc->object_offsets[i]; k < sc->object_offsets[i + 1]; ++k) {
            int odd;
            if (o->stiff_checker) {
                long long c = 0;
                for (int d = 0; d < 3; ++d) c += (long long)floor(P->x[3 * k + d] / o->stiff_cell);
                odd = (int)(c & 1);
            } else {
                odd = rng_uniform(&rng, 0.0, 1.0) < 0.5;
            }
            if (odd) P->mat[k] = o->stiff_mat;
        }
    }
}

static int parse_object(json_t *j, const char *file, const char *path, uint64_t index, const Scene *sc,
                        const char *asset_dir, double scale, ObjectSpec *o)
{
    int st = scene_keys_check(j, file, path, scene_object_keys, 0);
    if (st) return st;
    const char *s = NULL;
    char tmp[64];
    if ((st = read_name(j, "name", 0, file, path, tmp, sizeof tmp))) return st;
    if ((st = sj_string(j, "material", 1, file, path, &s, NULL))) return st;
    o->mat = -1;
    for (int k = 0; k < sc->n_materials; ++k)
        if (strcmp(sc->materials[k].name, s) == 0) o->mat = k;
    if (o->mat < 0) {
        char list[512] = "";
        size_t used = 0;
        for (int k = 0; k < sc->n_materials && used + 70 < sizeof list; ++k) {
            int w = snprintf(list + used, sizeof list - used, "%s%s", k ? ", " : "", sc->materials[k].name);
            if (w > 0) used += (size_t)w;
        }
        char p[512];
        sj_path(p, sizeof p, path, "material");
        return mpm_error(MPM_EINPUT, "%s: %s: unknown material \"%s\" (defined: %s)", file, p, s, list);
    }
    json_t *sh = json_object_get(j, "shape");
    char sp[512];
    sj_path(sp, sizeof sp, path, "shape");
    if (!sh) return mpm_error(MPM_EINPUT, "%s: %s: missing required field", file, sp);
    if ((st = sj_positive(j, "ppc", 1, file, path, &o->ppc, NULL))) return st;
    o->sampling = SAMPLING_POISSON;
    const char *samp = NULL;
    int have = 0;
    if ((st = sj_string(j, "sampling", 0, file, path, &samp, &have))) return st;
    if (have && !sampling_kind_from_string(samp, &o->sampling))
        return sj_bad(file, path, "sampling", "expected \"poisson\", \"random\" or \"lattice\"",
                      json_object_get(j, "sampling"));
    if (o->sampling == SAMPLING_LATTICE) {
        double k = round(cbrt(o->ppc));
        if (fabs(k * k * k - o->ppc) > 1e-9 * o->ppc)
            return sj_bad_number(file, path, "ppc", "expected a cube k^3 (1, 8, 27, ...) for lattice sampling",
                                 o->ppc);
    }
    if ((st = sj_vec3(j, "velocity", 0, file, path, o->velocity, NULL))) return st;
    json_t *fj = json_object_get(j, "initial_F");
    if (fj) {
        char fp[512];
        sj_path(fp, sizeof fp, path, "initial_F");
        if ((st = parse_initial_F(fj, file, fp, rng_mix(sc->seed, 0xF000ull + index), o))) return st;
    }
    json_t *vj = json_object_get(j, "variation");
    if (vj) {
        char vp[512];
        sj_path(vp, sizeof vp, path, "variation");
        if ((st = parse_variation(vj, file, vp, rng_mix(sc->seed, 0xC100ull + index), o))) return st;
    }
    json_t *svj = json_object_get(j, "stiffness_variation");
    if (svj) {
        char sp2[512];
        sj_path(sp2, sizeof sp2, path, "stiffness_variation");
        if ((st = parse_stiffness_variation(svj, file, sp2, sc->dx, rng_mix(sc->seed, 0x5E00ull + index), o)))
            return st;
    }
    if ((st = shape_parse(sh, file, sp, asset_dir, sc->dx, &o->shape))) return st;
    json_t *surf = json_object_get(j, "surface_particles");
    if (surf) {
        char up[512];
        sj_path(up, sizeof up, path, "surface_particles");
        if ((st = parse_surface(surf, file, up, asset_dir, sc->dx, scale, o))) return st;
    }
    if (!shape_is_bounded(o->shape))
        return mpm_error(MPM_EINPUT, "%s: %s: an object's shape must be bounded (got an unbounded %s)", file, sp,
                         shape_type_name(o->shape));
    double lo[3], hi[3];
    shape_bounds(o->shape, lo, hi);
    for (int d = 0; d < 3; ++d)
        if (hi[d] < sc->domain_lo[d] || lo[d] > sc->domain_hi[d])
            return mpm_error(MPM_EINPUT,
                             "%s: %s: object bounds [%g, %g, %g]-[%g, %g, %g] lie outside the domain "
                             "[%g, %g, %g]-[%g, %g, %g]",
                             file, sp, lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], sc->domain_lo[0], sc->domain_lo[1],
                             sc->domain_lo[2], sc->domain_hi[0], sc->domain_hi[1], sc->domain_hi[2]);
    return MPM_OK;
}

static int add_walls(Scene *sc, const char *file)
{
    static const char axes[3] = {'x', 'y', 'z'};
    for (int d = 0; d < 3; ++d)
        for (int side = 0; side < 2; ++side) {
            double point[3] = {0, 0, 0}, normal[3] = {0, 0, 0};
            point[d] = side ? sc->domain_hi[d] : sc->domain_lo[d];
            normal[d] = side ? -1.0 : 1.0; /* outward normal of the wall solid points into the domain */
            char name[32];
            snprintf(name, sizeof name, "wall_%c_%s", axes[d], side ? "max" : "min");
            json_t *j = json_pack("{s:s, s:s, s:{s:s, s:[f,f,f], s:[f,f,f]}}", "name", name, "type", "sticky",
                                  "shape", "type", "half_space", "point", point[0], point[1], point[2],
                                  "normal", normal[0], normal[1], normal[2]);
            if (!j) return mpm_error(MPM_EINTERNAL, "out of memory building domain walls");
            int st = collider_parse(j, file, "domain_walls", NULL, sc->dx, &sc->colliders[sc->n_colliders]);
            json_decref(j);
            if (st) return st;
            ++sc->n_colliders;
        }
    return MPM_OK;
}

/* The object's surface particles (the reference's .obj vertices): a
 * deterministic subset of round(N / scale^3) vertices of "vertices_of"
 * (evenly spaced in file order; all of them at scale 1), or that many
 * sampler_surface points with h = dx / 4. */
static int surface_points(const ObjectSpec *o, double dx, uint64_t seed, SamplePoints *pts)
{
    if (o->surf_n == 0) return MPM_OK;
    if (!o->surf_mesh) return sampler_surface(o->shape, o->surf_n, 0.25 * dx, seed, pts);
    double *v = NULL;
    size_t nv = 0;
    int st = shape_mesh_vertices(o->surf_mesh, &v, &nv);
    if (st) return st;
    size_t take = o->surf_n < nv ? o->surf_n : nv;
    SamplePoints tmp = {0};
    tmp.x = v;
    tmp.n = tmp.cap = nv;
    for (size_t k = 0; k < take && !st; ++k) {
        size_t idx = (size_t)((double)k * (double)nv / (double)take);
        if (idx >= nv) idx = nv - 1;
        if (pts->n == pts->cap) {
            size_t c = pts->cap ? 2 * pts->cap : 1024;
            double *q = realloc(pts->x, sizeof(double) * 3 * c);
            if (!q) {
                st = mpm_error(MPM_EINTERNAL, "out of memory adding surface particles");
                break;
            }
            pts->x = q;
            pts->cap = c;
        }
        memcpy(pts->x + 3 * pts->n++, v + 3 * idx, 3 * sizeof(double));
    }
    sample_points_free(&tmp);
    return st;
}

size_t scene_default_max_particles(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || page <= 0) return 1000000; /* unknown memory: a laptop's worth */
    double n = (double)pages * (double)page / 16384.0;
    return n < 10000 ? 10000 : (size_t)n;
}

int scene_parse_particle_budget(const char *flag, const char *text, size_t *out)
{
    char *end = NULL;
    double v = text && text[0] ? strtod(text, &end) : 0.0;
    if (!end || *end || !(v >= 1 && v <= 1e12) || v != floor(v))
        return mpm_error(MPM_EINPUT, "%s '%s': expected a whole number of particles in [1, 1e12]", flag,
                         text ? text : "");
    *out = (size_t)v;
    return MPM_OK;
}

static size_t budget_of(const SceneLoadOptions *opt)
{
    return opt && opt->max_particles ? opt->max_particles : scene_default_max_particles();
}

static void dx_text(char *buf, size_t n, double dx, double scale)
{
    if (scale != 1.0)
        snprintf(buf, n, "dx %g m (dx times --scale %g)", dx, scale);
    else
        snprintf(buf, n, "dx %g m", dx);
}

/* Before any sampling: the estimated particle count of every object, and
 * of all of them, against the budget. */
static int check_particle_budget(const Scene *sc, const char *file, ObjectSpec *objs, int nobj, double scale,
                                 size_t budget)
{
    double total = 0.0, largest = 0.0;
    int big = 0;
    char dxs[96];
    dx_text(dxs, sizeof dxs, sc->dx, scale);
    for (int i = 0; i < nobj; ++i) {
        ObjectSpec *o = &objs[i];
        double density = o->sampling == SAMPLING_LATTICE ? 1.0 : SAMPLER_DENSITY;
        double per_m3 = density * o->ppc / (sc->dx * sc->dx * sc->dx);
        double vol = shape_volume_bound(o->shape);
        double est = per_m3 * vol + (double)o->surf_n;
        if (!(est <= (double)budget)) { /* the cheap bound is loose for CSG: ask the real volume */
            o->volume = vol = shape_volume(o->shape);
            est = per_m3 * vol + (double)o->surf_n;
        }
        if (!(est <= (double)budget))
            return mpm_error(MPM_EINPUT,
                             "%s: objects.%d: ppc %g at %s in a volume of %g m^3 gives about %.3g particles "
                             "(%zu of them surface_particles), above the particle budget %zu (--max-particles)",
                             file, i, o->ppc, dxs, vol, est, o->surf_n, budget);
        total += est;
        if (est > largest) largest = est, big = i;
    }
    if (!(total <= (double)budget))
        return mpm_error(MPM_EINPUT,
                         "%s: objects: %d objects at %s give about %.3g particles in total (the most: objects.%d, "
                         "%.3g), above the particle budget %zu (--max-particles)",
                         file, nobj, dxs, total, big, largest, budget);
    return MPM_OK;
}

static int sample_objects(Scene *sc, const char *file, ObjectSpec *objs, int nobj, size_t budget)
{
    PoissonTile *own = NULL;
    const PoissonTile *tile = NULL;
    int st = MPM_OK;
    for (int i = 0; i < nobj && !st; ++i)
        if (objs[i].sampling == SAMPLING_POISSON) {
            tile = poisson_tile_shared(sc->seed);
            if (!tile) {
                st = poisson_tile_create(sc->seed, &own);
                tile = own;
            }
            break;
        }
    if (st) return st;
    sc->object_offsets = calloc((size_t)nobj + 1, sizeof(size_t));
    if (!sc->object_offsets) st = mpm_error(MPM_EINTERNAL, "out of memory");
    sc->n_objects = nobj;
    for (int i = 0; i < nobj && !st; ++i) {
        ObjectSpec *o = &objs[i];
        char path[64];
        sj_path_index(path, sizeof path, "objects", (size_t)i);
        SamplePoints pts;
        memset(&pts, 0, sizeof pts);
        st = surface_points(o, sc->dx, rng_mix(sc->seed, 0x5F00ull + (uint64_t)i), &pts);
        if (!st)
            st = sampler_sample(o->shape, o->sampling, sc->dx, o->ppc, rng_mix(sc->seed, 0x5A00ull + (uint64_t)i),
                                tile, &pts);
        if (st) { /* the sampler's message, prefixed with the place in the file */
            mpm_error_context(st, "%s: %s", file, path);
            break;
        }
        if (sc->particles.n + pts.n > budget) { /* the estimate is an estimate: the real count decides */
            st = mpm_error(MPM_EINPUT,
                           "%s: %s: sampling reached %zu particles (ppc %g at dx %g m), above the particle budget %zu "
                           "(--max-particles)",
                           file, path, sc->particles.n + pts.n, o->ppc, sc->dx, budget);
            sample_points_free(&pts);
            break;
        }
        if (pts.n == 0) {
            sample_points_free(&pts);
            st = mpm_error(MPM_EINPUT, "%s: %s: no particles sampled (shape smaller than the particle spacing at dx %g?)",
                           file, path, sc->dx);
            break;
        }
        double vol = o->volume > 0 ? o->volume : shape_volume(o->shape);
        double vp = vol / (double)pts.n, mass = sc->materials[o->mat].density * vp;
        /* a node's mass can be 1e-30 of a particle's (a B-spline weight near a
         * stencil's edge): far smaller particle masses underflow to zero node
         * masses and NaN velocities, far larger ones overflow the energy */
        if (!(vp > 0) || !isfinite(vp) || !(mass >= 1e-200 && mass <= 1e200)) {
            sample_points_free(&pts);
            char mp[512];
            sj_path(mp, sizeof mp, "materials", sc->materials[o->mat].name);
            st = mpm_error(MPM_EINPUT,
                           "%s: %s: particle volume %g m^3 and mass %g kg (%s.density %g) are not in [1e-200, 1e200]",
                           file, path, vp, mass, mp, sc->materials[o->mat].density);
            break;
        }
        for (size_t k = 0; k < pts.n; ++k) {
            const double *x = pts.x + 3 * k;
            for (int d = 0; d < 3; ++d)
                if (!(x[d] >= sc->domain_lo[d] && x[d] <= sc->domain_hi[d])) {
                    st = mpm_error(MPM_EINPUT,
                                   "%s: %s.shape: particle at (%g, %g, %g) lies outside the domain [%g, %g, %g]-[%g, "
                                   "%g, %g]",
                                   file, path, x[0], x[1], x[2], sc->domain_lo[0], sc->domain_lo[1],
                                   sc->domain_lo[2], sc->domain_hi[0], sc->domain_hi[1], sc->domain_hi[2]);
                    break;
                }
            if (st) break;
        }
        Particles *P = &sc->particles;
        size_t first = P->n;
        if (!st) st = particles_reserve(P, P->n + pts.n);
        Rng rng, flip; /* seeded even without initial_F: cheap, and no state is ever read uninitialised */
        double diag[3] = {1, 1, 1};
        rng_seed(&rng, o->F_seed);
        rng_seed(&flip, rng_mix(o->F_seed, 0x1F11ull)); /* its own stream: the diagonals stay as before */
        for (size_t k = 0; k < pts.n && !st; ++k) {
            st = particles_push(P, pts.x + 3 * k, o->velocity, mass, vp, o->mat);
            if (st || !o->has_F) continue;
            initial_F_diagonal(o, k, &rng, &flip, diag);
            double *F = P->F + 9 * (first + k);
            F[0] = diag[0], F[4] = diag[1], F[8] = diag[2];
        }
        sc->object_offsets[i + 1] = P->n;
        sample_points_free(&pts);
    }
    poisson_tile_free(own);
    return st;
}

/* Sources (core/source.h): each may add a sticky collider after the scene's
 * own colliders. */
static int parse_sources(Scene *sc, json_t *srcs, const char *file, const char *asset_dir)
{
    size_t ns = json_array_size(srcs);
    sc->sources = calloc(ns, sizeof(Source));
    if (!sc->sources) return mpm_error(MPM_EINTERNAL, "out of memory");
    const PoissonTile *tile = poisson_tile_shared(sc->seed);
    PoissonTile *own = NULL;
    int st = MPM_OK;
    if (!tile) {
        st = poisson_tile_create(sc->seed, &own);
        tile = own;
    }
    for (size_t i = 0; i < ns && !st; ++i) {
        char p[64], defname[64];
        sj_path_index(p, sizeof p, "sources", i);
        snprintf(defname, sizeof defname, "source%zu", i);
        Collider col;
        st = source_parse(json_array_get(srcs, i), file, p, asset_dir, sc->dx, sc->materials, sc->n_materials, tile,
                          defname, &sc->sources[i], &col);
        if (st) break;
        sc->n_sources = (int)i + 1;
        Source *s = &sc->sources[i];
        if (s->has_collider) sc->colliders[sc->n_colliders++] = col;
        /* the source must start inside the domain */
        double lo[3], hi[3], R[9], b[3];
        level_set_bounds(&s->pose.shape, lo, hi);
        collider_pose(&s->pose, 0.0, R, b);
        for (int c = 0; c < 8 && !st; ++c) {
            double X[3], d[3], x[3];
            for (int k = 0; k < 3; ++k) X[k] = (c >> k) & 1 ? hi[k] : lo[k];
            for (int k = 0; k < 3; ++k) d[k] = X[k] - s->pose.pivot0[k];
            m3_mulv(R, d, x);
            for (int k = 0; k < 3; ++k) x[k] += s->pose.pivot0[k] + b[k];
            for (int k = 0; k < 3; ++k)
                if (!(x[k] >= sc->domain_lo[k] && x[k] <= sc->domain_hi[k])) {
                    st = mpm_error(MPM_EINPUT,
                                   "%s: %s.shape: the source's bounds reach (%g, %g, %g), outside the domain "
                                   "[%g, %g, %g]-[%g, %g, %g]",
                                   file, p, x[0], x[1], x[2], sc->domain_lo[0], sc->domain_lo[1], sc->domain_lo[2],
                                   sc->domain_hi[0], sc->domain_hi[1], sc->domain_hi[2]);
                    break;
                }
        }
    }
    poisson_tile_free(own);
    return st;
}

/* ======================================================================
 * Top level
 * ====================================================================== */

/* What "transfer" may be: every name of core/transfer.h's table, or the
 * object form of PIC/FLIP. */
static void transfer_expected(char *out, size_t n)
{
    size_t len = (size_t)snprintf(out, n, "expected ");
    for (int i = 0; transfer_names[i] && len < n; ++i)
        len += (size_t)snprintf(out + len, n - len, "\"%s\", ", transfer_names[i]);
    if (len >= 2 && len < n)
        snprintf(out + len - 2, n - len + 2, " or {\"type\": \"%s\", \"alpha\": a}", transfer_kind_name(TRANSFER_PIC_FLIP));
}

/* The MPM variants of Gast et al. 2015 section 6 (each off by default):
 * "transfer", "position_update", "particle_volume". */
static int parse_mpm_options(json_t *root, const char *file, Scene *sc)
{
    int st, have = 0;
    const char *s = NULL;
    sc->transfer = TRANSFER_APIC;
    sc->flip_alpha = 0.95; /* Gast 6.1 step 5: "We typically used alpha = 0.95" */
    json_t *tj = json_object_get(root, "transfer");
    if (tj && json_is_object(tj)) {
        static const char *const tkeys[] = {"type", "alpha", NULL};
        if ((st = sj_check_object(tj, file, "transfer", tkeys))) return st;
        if ((st = sj_string(tj, "type", 1, file, "transfer", &s, NULL))) return st;
        TransferKind kind;
        if (!transfer_kind_from_name(s, &kind) || kind != TRANSFER_PIC_FLIP) {
            char what[96];
            snprintf(what, sizeof what, "expected \"%s\" (the object form is for PIC/FLIP)",
                     transfer_kind_name(TRANSFER_PIC_FLIP));
            return sj_bad(file, "transfer", "type", what, json_object_get(tj, "type"));
        }
        sc->transfer = TRANSFER_PIC_FLIP;
        if ((st = sj_number(tj, "alpha", 0, file, "transfer", &sc->flip_alpha, NULL))) return st;
        if (!(sc->flip_alpha >= 0 && sc->flip_alpha <= 1))
            return sj_bad_number(file, "transfer", "alpha", "expected a number in [0, 1]", sc->flip_alpha);
    } else if (tj) {
        if (!json_is_string(tj) || !transfer_kind_from_name(json_string_value(tj), &sc->transfer)) {
            char what[256];
            transfer_expected(what, sizeof what);
            return sj_bad(file, "", "transfer", what, tj);
        }
    }
    sc->position_update = POSITION_FORWARD_EULER;
    if ((st = sj_string(root, "position_update", 0, file, "", &s, &have))) return st;
    if (have) {
        if (strcmp(s, "backward_euler") == 0)
            sc->position_update = POSITION_BACKWARD_EULER;
        else if (strcmp(s, "forward_euler") != 0)
            return sj_bad(file, "", "position_update", "expected \"forward_euler\" or \"backward_euler\"",
                          json_object_get(root, "position_update"));
    }
    sc->volumes_from_density = 0;
    if ((st = sj_string(root, "particle_volume", 0, file, "", &s, &have))) return st;
    if (have) {
        if (strcmp(s, "grid_density") == 0)
            sc->volumes_from_density = 1;
        else if (strcmp(s, "shape") != 0)
            return sj_bad(file, "", "particle_volume", "expected \"shape\" or \"grid_density\"",
                          json_object_get(root, "particle_volume"));
    }
    return MPM_OK;
}

/* Every collider's surface speed over the domain must be finite in each of
 * its motion phases (an angular velocity of 1e308 deg/s overflows it), so
 * the CFL rule always sees a number. The first n_scene colliders are the
 * scene's "colliders" array, the rest come from "sources". */
static int check_collider_speeds(const Scene *sc, const char *file, size_t n_scene)
{
    for (int c = 0; c < sc->n_colliders; ++c) {
        const Collider *col = &sc->colliders[c];
        for (int k = 0; k < col->n_phases; ++k) {
            double t = col->phases[k].t_start;
            double v = collider_max_speed(col, t, sc->domain_lo, sc->domain_hi);
            if (isfinite(v)) continue;
            char where[64];
            if ((size_t)c < n_scene)
                snprintf(where, sizeof where, "colliders.%d", c);
            else
                snprintf(where, sizeof where, "sources (collider %d)", c);
            return mpm_error(MPM_EINPUT,
                             "%s: %s.motion.%d: collider \"%s\" moves at a non-finite speed (%g m/s) over the domain "
                             "from t = %g s: its velocity or angular_velocity_deg is too large",
                             file, where, k, col->name, v, t);
        }
    }
    return MPM_OK;
}

/* The grid must fit the domain: at least one cell across its smallest
 * extent, and integer node coordinates (|x / dx| < 2^30) everywhere in it. */
static int check_dx_against_domain(const Scene *sc, const char *file, double scale)
{
    double ext = HUGE_VAL, reach = 0.0;
    for (int d = 0; d < 3; ++d) {
        ext = fmin(ext, sc->domain_hi[d] - sc->domain_lo[d]);
        reach = fmax(reach, fmax(fabs(sc->domain_lo[d]), fabs(sc->domain_hi[d])));
    }
    char what[200], times[64] = "";
    if (scale != 1.0) snprintf(times, sizeof times, " (dx times --scale %g)", scale);
    if (!(sc->dx <= ext)) {
        snprintf(what, sizeof what, "expected at most the domain's smallest extent %g m%s", ext, times);
        return sj_bad_number(file, "", "dx", what, sc->dx);
    }
    double lo = reach / 1073741824.0;
    if (!(sc->dx >= lo)) {
        snprintf(what, sizeof what, "expected at least %g m%s (grid coordinates |x / dx| < 2^30 over the domain)", lo,
                 times);
        return sj_bad_number(file, "", "dx", what, sc->dx);
    }
    return MPM_OK;
}

/* min_dt, max_dt and cfl_rule, validated against the frame length 1/fps (a
 * frame of more than MAX_STEPS_PER_FRAME floor-sized steps is refused). */
enum { MAX_STEPS_PER_FRAME = 1000000 };

static int parse_time_steps(json_t *root, const char *file, Scene *sc)
{
    double frame = 1.0 / sc->fps;
    char what[160];
    sc->min_dt = 1e-6; /* the reference's floor (hot-algorithms.md 1.1) */
    int have_min = 0;
    int st = sj_positive(root, "min_dt", 0, file, "", &sc->min_dt, &have_min);
    if (st) return st;
    if (!have_min && !(sc->min_dt <= frame)) {
        snprintf(what, sizeof what, "expected at most 1/min_dt = %.6g frames per second", 1.0 / sc->min_dt);
        return sj_bad_number(file, "", "fps", what, sc->fps);
    }
    if (!(sc->min_dt * MAX_STEPS_PER_FRAME >= frame)) {
        snprintf(what, sizeof what, "expected at least the frame length 1/fps = %.6g s / %d", frame,
                 MAX_STEPS_PER_FRAME);
        return sj_bad_number(file, "", "min_dt", what, sc->min_dt);
    }
    if (!(sc->min_dt <= frame)) {
        snprintf(what, sizeof what, "expected at most the frame length 1/fps = %.6g s", frame);
        return sj_bad_number(file, "", "min_dt", what, sc->min_dt);
    }
    sc->max_dt = frame;
    if ((st = sj_positive(root, "max_dt", 0, file, "", &sc->max_dt, NULL))) return st;
    if (!(sc->max_dt >= sc->min_dt)) {
        snprintf(what, sizeof what, "expected at least min_dt = %.6g s (the smallest step)", sc->min_dt);
        return sj_bad_number(file, "", "max_dt", what, sc->max_dt);
    }
    const char *rule = "paper";
    int have = 0;
    if ((st = sj_string(root, "cfl_rule", 0, file, "", &rule, &have))) return st;
    if (strcmp(rule, "paper") == 0)
        sc->cfl_rule = CFL_RULE_PAPER;
    else if (strcmp(rule, "reference") == 0)
        sc->cfl_rule = CFL_RULE_REFERENCE;
    else
        return sj_bad(file, "", "cfl_rule", "expected \"paper\" or \"reference\"", json_object_get(root, "cfl_rule"));
    return MPM_OK;
}

static int build(json_t *root, const char *file, const SceneLoadOptions *opt, const char *asset_dir, Scene *sc)
{
    int st = scene_keys_check(root, file, "", scene_top_keys, 0);
    if (st) return st;
    if ((st = read_name(root, "name", 1, file, "", sc->name, sizeof sc->name))) return st;
    const char *desc = "";
    if ((st = sj_string(root, "description", 0, file, "", &desc, NULL))) return st;
    snprintf(sc->description, sizeof sc->description, "%s", desc);

    double scale = opt && opt->scale != 0.0 ? opt->scale : 1.0;
    if (!(scale > 0) || !isfinite(scale))
        return mpm_error(MPM_EINPUT, "%s: --scale: expected a positive number, got %g", file, scale);
    if ((st = sj_positive(root, "dx", 1, file, "", &sc->dx, NULL))) return st;
    sc->dx *= scale;
    if (!(sc->dx > 0) || !isfinite(sc->dx))
        return mpm_error(MPM_EINPUT, "%s: dx: dx times --scale %g is not a positive finite number", file, scale);
    if ((st = sj_positive(root, "fps", 1, file, "", &sc->fps, NULL))) return st;
    if (!isfinite(1.0 / sc->fps))
        return sj_bad_number(file, "", "fps", "expected a frame rate whose frame length 1/fps is finite", sc->fps);
    double frames = 0;
    if ((st = sj_number(root, "frames", 1, file, "", &frames, NULL))) return st;
    if (!(frames >= 1 && frames <= 1e9 && frames == floor(frames)))
        return sj_bad_number(file, "", "frames", "expected an integer >= 1", frames);
    sc->frames = (int)frames;
    sc->cfl = 0.6;
    if ((st = sj_positive(root, "cfl", 0, file, "", &sc->cfl, NULL))) return st;
    if ((st = parse_time_steps(root, file, sc))) return st;
    if ((st = sj_vec3(root, "gravity", 1, file, "", sc->gravity, NULL))) return st;
    sc->apic_ratio = 1.0;
    if ((st = sj_number(root, "apic_ratio", 0, file, "", &sc->apic_ratio, NULL))) return st;
    if (!(sc->apic_ratio >= 0 && sc->apic_ratio <= 1))
        return sj_bad_number(file, "", "apic_ratio", "expected a number in [0, 1]", sc->apic_ratio);
    if ((st = parse_mpm_options(root, file, sc))) return st;

    json_t *dom = json_object_get(root, "domain");
    if (!dom) return mpm_error(MPM_EINPUT, "%s: domain: missing required field", file);
    static const char *const dkeys[] = {"min", "max", NULL};
    if ((st = sj_check_object(dom, file, "domain", dkeys))) return st;
    if ((st = sj_vec3(dom, "min", 1, file, "domain", sc->domain_lo, NULL))) return st;
    if ((st = sj_vec3(dom, "max", 1, file, "domain", sc->domain_hi, NULL))) return st;
    for (int d = 0; d < 3; ++d)
        if (!(sc->domain_hi[d] > sc->domain_lo[d]) || !isfinite(sc->domain_hi[d] - sc->domain_lo[d]))
            return sj_bad(file, "domain", "max", "expected max > min on every axis (and a finite extent)",
                          json_object_get(dom, "max"));
    if ((st = check_dx_against_domain(sc, file, scale))) return st;
    int walls = 0;
    if ((st = sj_bool(root, "domain_walls", 0, file, "", &walls, NULL))) return st;
    sc->domain_walls = walls;
    sc->seed = 1;
    json_t *seed = json_object_get(root, "seed");
    if (seed) {
        if (!json_is_integer(seed) || json_integer_value(seed) < 0)
            return sj_bad(file, "", "seed", "expected a non-negative integer", seed);
        sc->seed = (unsigned long long)json_integer_value(seed);
    }

    /* materials */
    json_t *mats = json_object_get(root, "materials");
    if (!mats) return mpm_error(MPM_EINPUT, "%s: materials: missing required field", file);
    if (!json_is_object(mats) || json_object_size(mats) == 0)
        return sj_bad(file, "", "materials", "expected an object of named materials", mats);
    sc->materials = calloc(json_object_size(mats), sizeof(Material));
    if (!sc->materials) return mpm_error(MPM_EINTERNAL, "out of memory");
    const char *mname;
    json_t *mj;
    json_object_foreach(mats, mname, mj)
    {
        char p[512];
        sj_path(p, sizeof p, "materials", mname);
        if ((st = parse_material(mj, mname, file, p, &sc->materials[sc->n_materials]))) return st;
        Material *m = &sc->materials[sc->n_materials++];
        if (m->plasticity != PLASTICITY_NONE) sc->needs_plasticity = 1;
    }

    /* objects */
    json_t *objs = json_object_get(root, "objects");
    if (!objs) return mpm_error(MPM_EINPUT, "%s: objects: missing required field", file);
    json_t *srcs = json_object_get(root, "sources");
    if (srcs && (!json_is_array(srcs) || json_array_size(srcs) == 0))
        return sj_bad(file, "", "sources", "expected a non-empty array of sources", srcs);
    if (!json_is_array(objs) || (json_array_size(objs) == 0 && !srcs))
        return sj_bad(file, "", "objects", "expected a non-empty array of objects (empty only with \"sources\")",
                      objs);
    size_t nobj = json_array_size(objs);
    ObjectSpec *spec = calloc(nobj ? nobj : 1, sizeof *spec);
    if (!spec) return mpm_error(MPM_EINTERNAL, "out of memory");
    for (size_t i = 0; i < nobj && !st; ++i) {
        char p[64];
        sj_path_index(p, sizeof p, "objects", i);
        st = parse_object(json_array_get(objs, i), file, p, (uint64_t)i, sc, asset_dir, scale, &spec[i]);
    }
    if (!st) st = check_particle_budget(sc, file, spec, (int)nobj, scale, budget_of(opt));

    if (!st) st = add_stiffness_materials(sc, file, spec, (int)nobj);

    /* colliders */
    json_t *cols = json_object_get(root, "colliders");
    if (!st && cols && !json_is_array(cols))
        st = sj_bad(file, "", "colliders", "expected an array of colliders", cols);
    if (!st) {
        size_t nc = cols ? json_array_size(cols) : 0, ns = srcs ? json_array_size(srcs) : 0;
        sc->colliders = calloc(nc + ns + 6, sizeof(Collider));
        if (!sc->colliders) st = mpm_error(MPM_EINTERNAL, "out of memory");
        for (size_t i = 0; i < nc && !st; ++i) {
            char p[64], defname[64];
            sj_path_index(p, sizeof p, "colliders", i);
            snprintf(defname, sizeof defname, "collider%zu", i);
            st = collider_parse_named(json_array_get(cols, i), file, p, asset_dir, sc->dx, defname,
                                      &sc->colliders[sc->n_colliders]);
            if (!st) ++sc->n_colliders;
        }
        if (!st && ns) st = parse_sources(sc, srcs, file, asset_dir);
        for (int a = 0; a < sc->n_colliders && !st; ++a)
            for (int b = 0; b < a; ++b)
                if (strcmp(sc->colliders[a].name, sc->colliders[b].name) == 0) {
                    st = mpm_error(MPM_EINPUT, "%s: colliders.%d.name: duplicate collider name \"%s\"", file, a,
                                   sc->colliders[a].name);
                    break;
                }
        if (!st) st = check_collider_speeds(sc, file, nc);
        if (!st && walls) st = add_walls(sc, file);
    }

    if (!st) st = sample_objects(sc, file, spec, (int)nobj, budget_of(opt));
    if (!st && sc->needs_plasticity) {
        int snow = 0;
        for (int k = 0; k < sc->n_materials; ++k)
            snow |= sc->materials[k].plasticity == PLASTICITY_SNOW && sc->materials[k].hardening != 0.0;
        if (snow) st = particles_enable_plastic_state(&sc->particles); /* only hardening reads Jp */
    }
    if (!st) apply_variations(sc, spec, (int)nobj);
    if (!st) apply_stiffness_variations(sc, spec, (int)nobj);
    for (size_t i = 0; i < nobj; ++i) {
        shape_free(spec[i].shape);
        shape_free(spec[i].surf_mesh);
    }
    free(spec);
    return st;
}

/* Line `line` (1-based) of a text file, whitespace-trimmed and shortened,
 * so a JSON syntax error shows the field it is in. */
static void source_line(const char *path, int line, char *out, size_t n)
{
    out[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f) return;
    char buf[4096];
    int k = 0;
    while (fgets(buf, sizeof buf, f)) {
        size_t len = strlen(buf);
        if (++k == line) {
            while (len && (buf[len - 1] == '\n' || buf[len - 1] == '\r' || buf[len - 1] == ' ')) buf[--len] = '\0';
            const char *b = buf;
            while (*b == ' ' || *b == '\t') ++b;
            if (strlen(b) + 1 > n && n > 4)
                snprintf(out, n, "%.*s...", (int)(n - 4), b);
            else
                snprintf(out, n, "%s", b);
            break;
        }
        if (len && buf[len - 1] != '\n') { /* over-long line: skip the rest */
            int c;
            while ((c = fgetc(f)) != EOF && c != '\n') {
            }
        }
    }
    fclose(f);
}

int scene_load(const char *name_or_path, const SceneLoadOptions *opt, Scene *out)
{
    memset(out, 0, sizeof *out);
    if (!name_or_path || !name_or_path[0]) return mpm_error(MPM_EINPUT, "no scene given");
    char path[1024];
    if (is_builtin_name(name_or_path)) {
        snprintf(path, sizeof path, "%s/%s.json", scene_dir(), name_or_path);
        if (!file_exists(path)) {
            char **names;
            int n;
            char list[512] = "";
            if (list_names(&names, &n) == 0) {
                size_t used = 0;
                for (int k = 0; k < n && used + 70 < sizeof list; ++k) {
                    int w = snprintf(list + used, sizeof list - used, "%s%s", k ? ", " : "", names[k]);
                    if (w > 0) used += (size_t)w;
                }
                free_names(names, n);
            }
            return mpm_error(MPM_EINPUT, "unknown scene \"%s\" (built-in scenes in %s: %s)", name_or_path,
                             scene_dir(), list[0] ? list : "none");
        }
    } else {
        if (strlen(name_or_path) >= sizeof path)
            return mpm_error(MPM_EINPUT, "scene path too long: %.80s...", name_or_path);
        snprintf(path, sizeof path, "%s", name_or_path);
        struct stat sb;
        if (stat(path, &sb) != 0) return mpm_error(MPM_EINPUT, "%s: scene file not found (%s)", path, strerror(errno));
        if (S_ISDIR(sb.st_mode)) return mpm_error(MPM_EINPUT, "%s: is a directory, not a scene file", path);
        if (!S_ISREG(sb.st_mode))
            return mpm_error(MPM_EINPUT, "%s: not a regular file (a device or pipe), not a scene file", path);
        if (sb.st_size == 0) return mpm_error(MPM_EINPUT, "%s: empty file, not a scene file", path);
    }
    snprintf(out->path, sizeof out->path, "%s", path);

    json_error_t err;
    json_t *root = json_load_file(path, JSON_REJECT_DUPLICATES, &err);
    if (!root) {
        if (err.line > 0) {
            char src[96];
            source_line(path, err.line, src, sizeof src);
            return mpm_error(MPM_EINPUT, "%s:%d:%d: malformed JSON: %s (line %d: %s)", path, err.line, err.column,
                             err.text, err.line, src);
        }
        return mpm_error(MPM_EINPUT, "%s: cannot read scene file: %s", path, err.text);
    }
    int st = MPM_OK;
    if (opt)
        for (int k = 0; k < opt->n_overrides && !st; ++k) st = apply_override(root, path, &opt->overrides[k]);
    char adir[1024];
    if (opt && opt->asset_dir && opt->asset_dir[0]) {
        snprintf(adir, sizeof adir, "%s", opt->asset_dir);
    } else {
        const char *slash = strrchr(path, '/');
        if (slash)
            snprintf(adir, sizeof adir, "%.*s", (int)(slash - path), path);
        else
            snprintf(adir, sizeof adir, ".");
    }
    if (!st) st = build(root, path, opt, adir, out);
    json_decref(root);
    if (st) scene_free(out);
    return st;
}

void scene_free(Scene *s)
{
    if (!s) return;
    for (int k = 0; k < s->n_sources; ++k) source_free(&s->sources[k]);
    free(s->sources);
    free(s->materials);
    for (int k = 0; k < s->n_colliders; ++k) collider_free(&s->colliders[k]);
    free(s->colliders);
    particles_free(&s->particles);
    free(s->object_offsets);
    memset(s, 0, sizeof *s);
}
