/* Loading and validating experiment-matrix files (format in matrix_file.h). */
#include "experiments/matrix/matrix_file.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/error.h"
#include "core/scene/json_read.h"
#include "core/scene/scene_load.h"
#include "experiments/accuracy/error_ref.h"
#include "experiments/driver/registry.h"
#include "experiments/matrix/matrix_columns.h"
#include "experiments/matrix/matrix_keys.h"
#include "experiments/run/run.h"

void matrix_format_number(double v, char *out, size_t n)
{
    for (int p = 1; p <= 17; ++p) {
        snprintf(out, n, "%.*g", p, v);
        if (strtod(out, NULL) == v) return;
    }
}

/* Messages and key checks are the scene loader's (core/scene/json_read.h),
 * so a matrix file and a scene file report a bad value the same way. */
static int bad_value(const Matrix *m, const char *path, json_t *v, const char *expected)
{
    char want[300]; /* expected + the longest message text a caller passes */
    snprintf(want, sizeof want, "expected %s", expected);
    return sj_bad(m->base, path, NULL, want, v);
}

static int check_keys(const Matrix *m, json_t *obj, const char *path, const char *const *known)
{
    return sj_check_object(obj, m->base, path, known);
}

/* The matrix's own keys at place (matrix_keys.c), after the n already in keys. */
static void own_keys(MatrixKeyPlace place, const char **keys, int n, int cap)
{
    matrix_keys_at(place, keys + n, cap - n);
}

static int get_positive(const Matrix *m, json_t *v, const char *path, double *out)
{
    if (!json_is_number(v) || !(json_number_value(v) > 0.0) || !isfinite(json_number_value(v)))
        return bad_value(m, path, v, "a positive number");
    *out = json_number_value(v);
    return MPM_OK;
}

/* An integer key of the matrix's own, in its table line's range. */
static int get_int(const Matrix *m, json_t *v, const char *path, const MatrixKey *key, int *out)
{
    char want[64];
    if (key->max < OPT_INT_CAP) snprintf(want, sizeof want, "an integer %.0f..%.0f", key->min, key->max);
    else snprintf(want, sizeof want, "an integer >= %.0f", key->min);
    if (!json_is_integer(v) || json_integer_value(v) < key->min || json_integer_value(v) > key->max)
        return bad_value(m, path, v, want);
    *out = (int)json_integer_value(v);
    return MPM_OK;
}

static int get_bool(const Matrix *m, json_t *v, const char *path, int *out)
{
    if (!json_is_boolean(v)) return bad_value(m, path, v, "true or false");
    *out = json_is_true(v);
    return MPM_OK;
}

static int get_string(const Matrix *m, json_t *v, const char *path, char *out, size_t n)
{
    if (!json_is_string(v) || !json_string_value(v)[0]) return bad_value(m, path, v, "a non-empty string");
    if (strlen(json_string_value(v)) >= n) return bad_value(m, path, v, "a shorter string");
    snprintf(out, n, "%s", json_string_value(v));
    return MPM_OK;
}

const char *matrix_keep(Matrix *m, const char *text)
{
    if (m->n_pool == m->cap_pool) {
        int cap = m->cap_pool ? 2 * m->cap_pool : 64;
        char **p = realloc(m->pool, sizeof *p * (size_t)cap);
        if (!p) return NULL;
        m->pool = p;
        m->cap_pool = cap;
    }
    char *copy = strdup(text);
    if (copy) m->pool[m->n_pool++] = copy;
    return copy;
}

static int keep(Matrix *m, const char *text, const char **out)
{
    *out = matrix_keep(m, text);
    return *out ? MPM_OK : mpm_error(MPM_EINTERNAL, "out of memory");
}

void matrix_scene_path(const Matrix *m, const char *scene, char *out, size_t n)
{
    size_t len = strlen(scene);
    int builtin = !strchr(scene, '/') && !(len >= 5 && strcmp(scene + len - 5, ".json") == 0);
    if (builtin || scene[0] == '/') snprintf(out, n, "%s", scene);
    else snprintf(out, n, "%s/%s", m->dir, scene);
}

static int file_exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

static int check_scene(const Matrix *m, const char *path, const char *scene)
{
    char p[2048];
    matrix_scene_path(m, scene, p, sizeof p);
    if (strcmp(p, scene) == 0 && !strchr(scene, '/')) { /* built-in name */
        char f[2048];
        snprintf(f, sizeof f, "%s/%s.json", scene_dir(), scene);
        if (!file_exists(f))
            return mpm_error(MPM_EINPUT, "%s: %s: unknown scene \"%s\" (not in %s; see: mpmbench list scenes)", m->base,
                             path, scene, scene_dir());
    } else if (!file_exists(p)) {
        return mpm_error(MPM_EINPUT, "%s: %s: scene file \"%s\" not found (%s)", m->base, path, scene, p);
    }
    return MPM_OK;
}

static int resolve_dir(const Matrix *m, const char *path, const char *given, char *out, size_t n)
{
    int w = given[0] == '/' ? snprintf(out, n, "%s", given) : snprintf(out, n, "%s/%s", m->dir, given);
    if (w < 0 || (size_t)w >= n) return mpm_error(MPM_EINPUT, "%s: %s: path too long", m->base, path);
    return MPM_OK;
}

/* The value of run setting o (not a list) at path: the JSON type and range
 * its table line asks for, its check, and what the matrix file means by it
 * (OPT_KEY_*). Texts are kept in the matrix's pool. */
static int get_setting(Matrix *m, const Option *o, json_t *v, const char *path, OptionValue *out)
{
    char want[256];
    option_expect(o, 1, want, sizeof want);
    memset(out, 0, sizeof *out);
    switch (o->type) {
    case OPT_SWITCH:
        if (!json_is_boolean(v)) return bad_value(m, path, v, "true or false");
        out->i = json_is_true(v);
        return MPM_OK;
    case OPT_INT:
        if (!json_is_integer(v) || !option_in_range(o, (double)json_integer_value(v))) return bad_value(m, path, v, want);
        out->i = (int)json_integer_value(v);
        return MPM_OK;
    case OPT_REAL:
        if (!json_is_number(v) || !option_in_range(o, json_number_value(v))) return bad_value(m, path, v, want);
        out->d = json_number_value(v);
        return MPM_OK;
    case OPT_SIZE:
        if (!json_is_number(v) || !option_in_range(o, json_number_value(v))) return bad_value(m, path, v, want);
        out->z = (size_t)json_number_value(v);
        return MPM_OK;
    case OPT_CHOICE:
        if (json_is_string(v))
            for (int k = 0; o->choices[k]; ++k)
                if (!strcmp(json_string_value(v), o->choices[k])) {
                    out->i = k;
                    return MPM_OK;
                }
        return bad_value(m, path, v, want);
    case OPT_TEXT:
        break;
    case OPT_LIST:
        return mpm_error(MPM_EINTERNAL, "%s: %s: a list setting read as one value", m->base, path);
    }
    if (o->flags & OPT_KEY_SUBDIR) { /* true: the folder named by the key in the cell's folder */
        if (!json_is_boolean(v)) return bad_value(m, path, v, "true or false");
        out->s = json_is_true(v) ? o->key : NULL;
        return MPM_OK;
    }
    char text[1024], dir[1024];
    int st = get_string(m, v, path, text, sizeof text);
    if (st) return st;
    if ((o->flags & OPT_KEY_SCENE) && (st = check_scene(m, path, text))) return st;
    if (o->flags & OPT_KEY_DIR) {
        if ((st = resolve_dir(m, path, text, dir, sizeof dir))) return st;
        snprintf(text, sizeof text, "%s", dir);
    }
    if (o->check && o->check(text) != MPM_OK) {
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", mpm_last_error());
        mpm_clear_error();
        return mpm_error(MPM_EINPUT, "%s: %s: %s", m->base, path, msg);
    }
    return keep(m, text, &out->s);
}

static int get_solver(Matrix *m, json_t *v, const char *path, const char **out)
{
    OptionValue val;
    int st = get_setting(m, run_setting_by_key("solver"), v, path, &val);
    *out = val.s;
    return st;
}

/* A set / solver_opts object into key=value text, merged on top of `list`. */
static int get_kv(const Matrix *m, json_t *obj, const char *path, MatrixNamedKind kind, MatrixKvList *list)
{
    if (!json_is_object(obj)) return bad_value(m, path, obj, "an object of key: value");
    size_t key_cap = kind == MATRIX_SET ? sizeof list->kv[0].key : 32;
    size_t val_cap = kind == MATRIX_SET ? sizeof list->kv[0].value : 64;
    const char *key;
    json_t *v;
    json_object_foreach(obj, key, v) {
        char p[256], text[256];
        sj_path(p, sizeof p, path, key);
        if (!key[0] || strlen(key) >= key_cap || strchr(key, '=') || strchr(key, ','))
            return mpm_error(MPM_EINPUT, "%s: %s: bad key \"%s\" (non-empty, under %zu characters, no '=' or ',')",
                             m->base, path, key, key_cap);
        if (json_is_string(v)) {
            if (!json_string_value(v)[0]) return bad_value(m, p, v, "a non-empty value");
            snprintf(text, sizeof text, "%s", json_string_value(v));
        } else if (json_is_integer(v)) {
            snprintf(text, sizeof text, "%lld", (long long)json_integer_value(v));
        } else if (json_is_real(v)) {
            if (!isfinite(json_real_value(v))) return bad_value(m, p, v, "a finite number");
            matrix_format_number(json_real_value(v), text, sizeof text);
        } else if (json_is_boolean(v)) {
            snprintf(text, sizeof text, "%s", kind == MATRIX_SET ? (json_is_true(v) ? "true" : "false")
                                                                 : (json_is_true(v) ? "1" : "0"));
        } else if (kind == MATRIX_SET && (json_is_array(v) || json_is_object(v))) {
            char *s = json_dumps(v, JSON_COMPACT | JSON_REAL_PRECISION(17));
            if (!s) return mpm_error(MPM_EINTERNAL, "out of memory");
            snprintf(text, sizeof text, "%s", s);
            size_t len = strlen(s);
            free(s);
            if (len >= sizeof text) return bad_value(m, p, v, "a shorter value");
        } else {
            return bad_value(m, p, v, kind == MATRIX_SET ? "a JSON value" : "a number, string or boolean");
        }
        if (strlen(text) >= val_cap) return bad_value(m, p, v, "a shorter value");
        if (strpbrk(text, "\n\r")) return bad_value(m, p, v, "a value on one line");
        if (kind == MATRIX_SOLVER_OPTS && strchr(text, ','))
            return bad_value(m, p, v, "a value without ','");
        int slot = -1;
        for (int i = 0; i < list->n; ++i)
            if (strcmp(list->kv[i].key, key) == 0) slot = i;
        if (slot < 0) {
            if (list->n >= MATRIX_MAX_KV)
                return mpm_error(MPM_EINPUT, "%s: %s: more than %d entries", m->base, path, MATRIX_MAX_KV);
            slot = list->n++;
        }
        snprintf(list->kv[slot].key, sizeof list->kv[slot].key, "%s", key);
        snprintf(list->kv[slot].value, sizeof list->kv[slot].value, "%s", text);
        snprintf(list->kv[slot].origin, sizeof list->kv[slot].origin, "%s", p);
    }
    return MPM_OK;
}

/* "reference": a solver and optionally eps, solver options and --set
 * overrides (matrix_keys.c; false per scene: none). */
static int get_reference(Matrix *m, json_t *v, const char *path, int allow_false, MatrixReference *r)
{
    const char *keys[16];
    own_keys(MATRIX_AT_REFERENCE, keys, 0, 16);
    memset(r, 0, sizeof *r);
    snprintf(r->origin, sizeof r->origin, "%s", path);
    if (allow_false && json_is_false(v)) return MPM_OK;
    if (!json_is_object(v))
        return bad_value(m, path, v, allow_false ? "an object {\"solver\": ...} or false" : "an object {\"solver\": ...}");
    int st = check_keys(m, v, path, keys);
    if (st) return st;
    char p[300];
    json_t *s = json_object_get(v, "solver");
    sj_path(p, sizeof p, path, "solver");
    if (!s) return mpm_error(MPM_EINPUT, "%s: %s: missing (required)", m->base, p);
    if ((st = get_solver(m, s, p, &r->solver)) || (st = keep(m, p, &r->solver_origin))) return st;
    r->eps = MATRIX_REFERENCE_EPS;
    json_t *e = json_object_get(v, "eps");
    sj_path(p, sizeof p, path, "eps");
    OptionValue eps;
    if (e && (st = get_setting(m, run_setting_by_key("eps"), e, p, &eps))) return st;
    if (e) r->eps = eps.d;
    json_t *o = json_object_get(v, "solver_opts");
    sj_path(p, sizeof p, path, "solver_opts");
    if (o && (st = get_kv(m, o, p, MATRIX_SOLVER_OPTS, &r->solver_opts))) return st;
    json_t *sv = json_object_get(v, "set");
    sj_path(p, sizeof p, path, "set");
    if (sv && (st = get_kv(m, sv, p, MATRIX_SET, &r->set))) return st;
    json_t *sf = json_object_get(v, "sample_frames");
    sj_path(p, sizeof p, path, "sample_frames");
    if (sf) {
        if (!json_is_string(sf)) return bad_value(m, p, sf, "a text of increasing frame numbers \"F,F,...\"");
        if ((st = run_check_sample_frames(json_string_value(sf)))) return mpm_error_context(st, "%s: %s", m->base, p);
        if ((st = keep(m, json_string_value(sf), &r->sample_frames))) return st;
    }
    r->has = 1;
    return MPM_OK;
}

#define SETTINGS_KEYS_MAX (RUN_SETTINGS_MAX + 8)

/* The keys a settings object may have: every run setting with a key
 * allowed there, then the matrix's own keys. NULL-terminated. */
static void settings_keys(int per_scene, const char **keys)
{
    int n = 0;
    for (int k = 0; k < run_settings_count; ++k) {
        const Option *o = &run_settings[k];
        if (o->key && (o->flags & (per_scene ? OPT_IN_SCENES : OPT_IN_DEFAULTS))) keys[n++] = o->key;
    }
    own_keys(MATRIX_AT_SETTINGS, keys, n, SETTINGS_KEYS_MAX);
    while (keys[n]) ++n;
    if (per_scene) own_keys(MATRIX_AT_SCENE, keys, n, SETTINGS_KEYS_MAX);
}

/* "defaults" or a per-scene entry "scenes.NAME". */
static int get_settings(Matrix *m, json_t *obj, const char *path, int per_scene, MatrixSettings *s)
{
    const char *keys[SETTINGS_KEYS_MAX];
    settings_keys(per_scene, keys);
    if (!json_is_object(obj)) return bad_value(m, path, obj, "an object");
    int st = check_keys(m, obj, path, keys);
    if (st) return st;
    const char *key;
    json_t *v;
    json_object_foreach(obj, key, v) {
        char p[256];
        sj_path(p, sizeof p, path, key);
        int k = run_setting_index(key);
        if (k >= 0 && run_settings[k].type == OPT_LIST) {
            st = get_kv(m, v, p, run_settings[k].flags & OPT_KEY_JSON ? MATRIX_SET : MATRIX_SOLVER_OPTS,
                        run_settings[k].flags & OPT_KEY_JSON ? &s->set : &s->solver_opts);
            if (!st && !(st = keep(m, p, &s->origin[k]))) s->given |= 1ull << k;
        } else if (k >= 0) {
            OptionValue val;
            if (!(st = get_setting(m, &run_settings[k], v, p, &val)) && !(st = keep(m, p, &s->origin[k]))) {
                option_set(&run_settings[k], &s->run, &val);
                s->given |= 1ull << k;
            }
        } else if (!strcmp(key, "first_timed_frame")) {
            st = get_int(m, v, p, matrix_key(MATRIX_AT_SETTINGS, key), &s->first_timed_frame);
            s->has_first = 1;
        } else if (!strcmp(key, "reference")) {
            st = get_reference(m, v, p, 1, &s->reference);
            s->has_reference = 1;
        }
        if (st) return st;
    }
    int kf = run_setting_index("frames");
    if ((s->given >> kf & 1) && s->has_first && s->first_timed_frame >= s->run.frames) {
        char p[256];
        sj_path(p, sizeof p, path, "first_timed_frame");
        return bad_value(m, p, json_object_get(obj, "first_timed_frame"), "a frame before \"frames\"");
    }
    return MPM_OK;
}

/* A non-empty JSON array at path, or the error. */
static int get_list(const Matrix *m, json_t *v, const char *path, size_t *n)
{
    if (!json_is_array(v)) return bad_value(m, path, v, "a list of values");
    if (json_array_size(v) == 0)
        return mpm_error(MPM_EINPUT, "%s: %s: empty list (an axis needs at least one value)", m->base, path);
    *n = json_array_size(v);
    return MPM_OK;
}

static int check_axis_name(const Matrix *m, const char *path, const char *name)
{
    int ok = name[0] >= 'a' && name[0] <= 'z' && strlen(name) <= MATRIX_AXIS_NAME_MAX;
    for (const char *c = name; *c && ok; ++c) ok = islower((unsigned char)*c) || isdigit((unsigned char)*c) || *c == '_';
    if (!ok)
        return mpm_error(MPM_EINPUT, "%s: %s: axis name \"%s\": expected [a-z][a-z0-9_]*, under %d characters",
                         m->base, path, name, MATRIX_AXIS_NAME_MAX + 1);
    if (matrix_column_reserved(name))
        return mpm_error(MPM_EINPUT, "%s: %s: axis name \"%s\" is a built-in column name", m->base, path, name);
    if (matrix_named_index(m, name) >= 0)
        return mpm_error(MPM_EINPUT, "%s: %s: axis name \"%s\" is used twice", m->base, path, name);
    return MPM_OK;
}

/* Label of a set given as a list element: its value for one key, else
 * k=v;k=v. -1 when it does not fit. */
static int auto_label(const MatrixKvList *kv, char *out, size_t n)
{
    if (kv->n == 1) return snprintf(out, n, "%s", kv->kv[0].value) < (int)n ? 0 : -1;
    size_t len = 0;
    out[0] = '\0';
    for (int i = 0; i < kv->n; ++i) {
        int w = snprintf(out + len, n - len, "%s%s=%s", i ? ";" : "", kv->kv[i].key, kv->kv[i].value);
        if (w < 0 || (size_t)w >= n - len) return -1;
        len += (size_t)w;
    }
    return 0;
}

static int get_named_axes(Matrix *m, json_t *obj, const char *path, MatrixNamedKind kind)
{
    if (!json_is_object(obj)) return bad_value(m, path, obj, "an object of named axes");
    const char *name;
    json_t *axis;
    json_object_foreach(obj, name, axis) {
        char ap[256];
        sj_path(ap, sizeof ap, path, name);
        int st = check_axis_name(m, path, name);
        if (st) return st;
        if (m->n_named >= MATRIX_MAX_AXES)
            return mpm_error(MPM_EINPUT, "%s: %s: more than %d named axes", m->base, path, MATRIX_MAX_AXES);
        size_t n = 0;
        if (json_is_object(axis)) {
            n = json_object_size(axis);
            if (!n) return mpm_error(MPM_EINPUT, "%s: %s: empty (an axis needs at least one value)", m->base, ap);
        } else if ((st = get_list(m, axis, ap, &n))) {
            return st;
        }
        MatrixNamedAxis *a = &m->named[m->n_named];
        memset(a, 0, sizeof *a);
        snprintf(a->name, sizeof a->name, "%s", name);
        a->kind = kind;
        if (!(a->values = calloc(n, sizeof *a->values))) return mpm_error(MPM_EINTERNAL, "out of memory");
        m->n_named++;
        if (json_is_object(axis)) {
            const char *label;
            json_t *set;
            json_object_foreach(axis, label, set) {
                char p[320];
                snprintf(p, sizeof p, "%s.%s", ap, label);
                if (!label[0] || strlen(label) >= sizeof a->values[0].label)
                    return mpm_error(MPM_EINPUT, "%s: %s: bad label \"%s\"", m->base, ap, label);
                snprintf(a->values[a->n].label, sizeof a->values[0].label, "%s", label);
                if ((st = get_kv(m, set, p, kind, &a->values[a->n].kv))) return st;
                a->n++;
            }
        } else {
            for (size_t i = 0; i < n; ++i) {
                char p[320];
                snprintf(p, sizeof p, "%s[%zu]", ap, i);
                if ((st = get_kv(m, json_array_get(axis, i), p, kind, &a->values[a->n].kv))) return st;
                if (a->values[a->n].kv.n == 0)
                    return bad_value(m, p, json_array_get(axis, i), "a non-empty set");
                if (auto_label(&a->values[a->n].kv, a->values[a->n].label, sizeof a->values[0].label))
                    return mpm_error(MPM_EINPUT, "%s: %s: label too long (give labels: {\"LABEL\": set})", m->base, p);
                for (int k = 0; k < a->n; ++k)
                    if (!strcmp(a->values[k].label, a->values[a->n].label))
                        return mpm_error(MPM_EINPUT, "%s: %s: same label \"%s\" as %s[%d] (give labels: {\"LABEL\": set})",
                                         m->base, p, a->values[a->n].label, ap, k);
                a->n++;
            }
        }
    }
    return MPM_OK;
}

static int is_axis(int k) { return k >= 0 && (run_settings[k].flags & OPT_AXIS); }

static int get_axes(Matrix *m, json_t *axes)
{
    const char *keys[SETTINGS_KEYS_MAX];
    int n_keys = 0;
    for (int k = 0; k < run_settings_count; ++k)
        if (is_axis(k)) keys[n_keys++] = run_settings[k].key;
    own_keys(MATRIX_AT_AXES, keys, n_keys, SETTINGS_KEYS_MAX);
    if (!json_is_object(axes)) return bad_value(m, "axes", axes, "an object");
    int st = check_keys(m, axes, "axes", keys);
    if (st) return st;
    for (int k = 0; k < run_settings_count; ++k) {
        json_t *v = is_axis(k) ? json_object_get(axes, run_settings[k].key) : NULL;
        if (!v) continue;
        char p[300];
        size_t n = 0;
        snprintf(p, sizeof p, "axes.%s", run_settings[k].key);
        if ((st = get_list(m, v, p, &n))) return st;
        MatrixAxis *a = &m->axis[k];
        a->values = calloc(n, sizeof *a->values);
        a->origins = calloc(n, sizeof *a->origins);
        if (!a->values || !a->origins) return mpm_error(MPM_EINTERNAL, "out of memory");
        for (size_t i = 0; i < n; ++i, a->n++) {
            snprintf(p, sizeof p, "axes.%s[%zu]", run_settings[k].key, i);
            if ((st = get_setting(m, &run_settings[k], json_array_get(v, i), p, &a->values[i])) ||
                (st = keep(m, p, &a->origins[i])))
                return st;
        }
    }
    json_t *v;
    if ((v = json_object_get(axes, "sets")) && (st = get_named_axes(m, v, "axes.sets", MATRIX_SET))) return st;
    if ((v = json_object_get(axes, "solver_opts")) &&
        (st = get_named_axes(m, v, "axes.solver_opts", MATRIX_SOLVER_OPTS)))
        return st;
    return MPM_OK;
}

int matrix_named_index(const Matrix *m, const char *name)
{
    for (int i = 0; i < m->n_named; ++i)
        if (!strcmp(m->named[i].name, name)) return i;
    return -1;
}

int matrix_axis_length(const Matrix *m, const char *key)
{
    int k = run_setting_index(key);
    return k >= 0 ? m->axis[k].n : 0;
}

/* Does the matrix have `text` as a value of the text setting k (its axis, or
 * else the defaults' value) or of the named axis `key` (a label)? */
static int has_string_value(const Matrix *m, const char *key, const char *text)
{
    int k = run_setting_index(key);
    if (k >= 0) {
        const MatrixAxis *a = &m->axis[k];
        OptionValue d;
        option_get(&run_settings[k], &m->defaults.run, &d);
        if (!a->n) return (m->defaults.given >> k & 1) && d.s && !strcmp(d.s, text);
        for (int i = 0; i < a->n; ++i)
            if (!strcmp(a->values[i].s, text)) return 1;
        return 0;
    }
    const MatrixNamedAxis *a = &m->named[matrix_named_index(m, key)];
    for (int i = 0; i < a->n; ++i)
        if (!strcmp(a->values[i].label, text)) return 1;
    return 0;
}

/* One rule value: the right type, and (texts, labels) a value the matrix has. */
static int check_rule_value(Matrix *m, const char *key, json_t *v, const char *path)
{
    int k = run_setting_index(key);
    if (k >= 0 && run_settings[k].type != OPT_TEXT) {
        OptionValue x;
        return get_setting(m, &run_settings[k], v, path, &x);
    }
    char text[256];
    if (json_is_number(v) && k < 0)
        matrix_format_number(json_number_value(v), text, sizeof text);
    else if (!json_is_string(v))
        return bad_value(m, path, v, "a string (a value of that axis)");
    else
        snprintf(text, sizeof text, "%s", json_string_value(v));
    if (!has_string_value(m, key, text))
        return mpm_error(MPM_EINPUT, "%s: %s: \"%s\" is not a value of the matrix's %s", m->base, path, text, key);
    return MPM_OK;
}

static int get_rules(Matrix *m, json_t *rules, const char *path)
{
    if (!json_is_array(rules)) return bad_value(m, path, rules, "a list of rules");
    for (size_t i = 0; i < json_array_size(rules); ++i) {
        json_t *r = json_array_get(rules, i);
        char rp[64];
        snprintf(rp, sizeof rp, "%s[%zu]", path, i);
        if (!json_is_object(r) || !json_object_size(r)) return bad_value(m, rp, r, "a non-empty object {axis: value(s)}");
        const char *key;
        json_t *v;
        json_object_foreach(r, key, v) {
            char p[160];
            snprintf(p, sizeof p, "%s.%s", rp, key);
            if (matrix_named_index(m, key) < 0 && !is_axis(run_setting_index(key))) {
                char axes[256] = "";
                size_t len = 0;
                for (int k = 0; k < run_settings_count && len < sizeof axes; ++k)
                    if (is_axis(k)) len += (size_t)snprintf(axes + len, sizeof axes - len, "%s, ", run_settings[k].key);
                if (len >= 2 && len < sizeof axes) axes[len - 2] = '\0';
                return mpm_error(MPM_EINPUT, "%s: %s: unknown axis \"%s\" (%s or a named axis)", m->base, rp, key, axes);
            }
            int st;
            if (json_is_array(v)) {
                if (!json_array_size(v)) return bad_value(m, p, v, "a value or a non-empty list");
                for (size_t k = 0; k < json_array_size(v); ++k) {
                    char q[192];
                    snprintf(q, sizeof q, "%s[%zu]", p, k);
                    if ((st = check_rule_value(m, key, json_array_get(v, k), q))) return st;
                }
            } else if ((st = check_rule_value(m, key, v, p))) {
                return st;
            }
        }
    }
    return MPM_OK;
}

static int get_top(Matrix *m)
{
    const char *keys[SETTINGS_KEYS_MAX];
    own_keys(MATRIX_AT_TOP, keys, 0, SETTINGS_KEYS_MAX);
    json_t *root = m->root;
    m->description = "";
    m->repeat = 1;
    if (!json_is_object(root)) return bad_value(m, "(top level)", root, "an object");
    int st = check_keys(m, root, "", keys);
    if (st) return st;
    json_t *v = json_object_get(root, "name");
    if (!v) return mpm_error(MPM_EINPUT, "%s: name: missing (required)", m->base);
    if ((st = get_string(m, v, "name", m->name, sizeof m->name))) return st;
    for (const char *c = m->name; *c; ++c)
        if (!isalnum((unsigned char)*c) && *c != '_' && *c != '-' && *c != '.')
            return bad_value(m, "name", v, MATRIX_NAME_RULE);
    if ((v = json_object_get(root, "description"))) {
        if (!json_is_string(v)) return bad_value(m, "description", v, "a string");
        m->description = json_string_value(v); /* any length: root keeps it */
    }
    if ((v = json_object_get(root, "defaults")) && (st = get_settings(m, v, "defaults", 0, &m->defaults))) return st;
    if ((v = json_object_get(root, "axes")) && (st = get_axes(m, v))) return st;
    for (int k = 0; k < run_settings_count; ++k) /* a cell names its scene and solver */
        if ((run_settings[k].flags & OPT_ARGV_ALWAYS) && run_settings[k].type == OPT_TEXT && !m->axis[k].n &&
            !(m->defaults.given >> k & 1))
            return mpm_error(MPM_EINPUT, "%s: axes.%s: missing (give axes.%s or defaults.%s)", m->base,
                             run_settings[k].key, run_settings[k].key, run_settings[k].key);
    if ((v = json_object_get(root, "scenes"))) {
        if (!json_is_object(v)) return bad_value(m, "scenes", v, "an object {scene: settings}");
        if (!(m->per_scene = calloc(json_object_size(v) + 1, sizeof *m->per_scene)))
            return mpm_error(MPM_EINTERNAL, "out of memory");
        const char *scene;
        json_t *s;
        json_object_foreach(v, scene, s) {
            char p[1100];
            snprintf(p, sizeof p, "scenes.%s", scene);
            if (!has_string_value(m, "scene", scene))
                return mpm_error(MPM_EINPUT, "%s: %s: \"%s\" is not a scene of the matrix", m->base, p, scene);
            MatrixSceneSettings *ps = &m->per_scene[m->n_per_scene++];
            snprintf(ps->scene, sizeof ps->scene, "%s", scene);
            if ((st = get_settings(m, s, p, 1, &ps->s))) return st;
        }
    }
    if ((v = json_object_get(root, "reference")) && (st = get_reference(m, v, "reference", 0, &m->reference)))
        return st;
    m->has_references = m->reference.has;
    m->has_samples = m->reference.has && m->reference.sample_frames;
    int ke = run_setting_index("error_ref");
    int kr = run_setting_index("ranks");
    m->uses_error_ref = (m->defaults.given >> ke & 1) || m->axis[ke].n > 0;
    m->uses_ranks = (m->defaults.given >> kr & 1) || m->axis[kr].n > 0;
    for (int i = 0; i < m->n_per_scene; ++i) {
        const MatrixSettings *ps = &m->per_scene[i].s;
        m->uses_error_ref |= ps->given >> ke & 1;
        m->uses_ranks |= ps->given >> kr & 1;
        m->has_references |= ps->has_reference && ps->reference.has;
        m->has_samples |= ps->has_reference && ps->reference.has && ps->reference.sample_frames;
    }
    if ((v = json_object_get(root, "include"))) {
        if ((st = get_rules(m, v, "include"))) return st;
        m->include = v;
    }
    if ((v = json_object_get(root, "exclude"))) {
        if ((st = get_rules(m, v, "exclude"))) return st;
        m->exclude = v;
    }
    if ((v = json_object_get(root, "baseline"))) {
        const char *baseline;
        if ((st = get_solver(m, v, "baseline", &baseline))) return st;
        snprintf(m->baseline, sizeof m->baseline, "%s", baseline);
        if (!has_string_value(m, "solver", m->baseline))
            return mpm_error(MPM_EINPUT, "%s: baseline: \"%s\" is not a solver of the matrix", m->base, m->baseline);
    }
    if ((v = json_object_get(root, "cell_timeout_s")) && (st = get_positive(m, v, "cell_timeout_s", &m->cell_timeout_s)))
        return st;
    if ((v = json_object_get(root, "repeat")) && (st = get_int(m, v, "repeat", matrix_key(MATRIX_AT_TOP, "repeat"), &m->repeat)))
        return st;
    if ((v = json_object_get(root, "report"))) {
        const char *rk[8];
        own_keys(MATRIX_AT_REPORT, rk, 0, 8);
        if (!json_is_object(v)) return bad_value(m, "report", v, "an object");
        if ((st = check_keys(m, v, "report", rk))) return st;
        json_t *g = json_object_get(v, "mg_levels");
        if (g && (st = get_bool(m, g, "report.mg_levels", &m->report_mg_levels))) return st;
    }
    return MPM_OK;
}

int matrix_load(const char *path, Matrix *m)
{
    memset(m, 0, sizeof *m);
    snprintf(m->file, sizeof m->file, "%s", path);
    const char *slash = strrchr(path, '/');
    snprintf(m->base, sizeof m->base, "%s", slash ? slash + 1 : path);
    if (slash) snprintf(m->dir, sizeof m->dir, "%.*s", (int)(slash - path), path);
    else snprintf(m->dir, sizeof m->dir, ".");
    if (!m->dir[0]) snprintf(m->dir, sizeof m->dir, "/");
    json_error_t err;
    m->root = json_load_file(path, JSON_REJECT_DUPLICATES, &err);
    if (!m->root) {
        if (err.line > 0)
            return mpm_error(MPM_EINPUT, "%s:%d:%d: malformed JSON: %s", path, err.line, err.column, err.text);
        return mpm_error(MPM_EINPUT, "%s: cannot read matrix file: %s", path, err.text);
    }
    return get_top(m);
}

void matrix_free(Matrix *m)
{
    for (int k = 0; k < RUN_SETTINGS_MAX; ++k) {
        free(m->axis[k].values);
        free(m->axis[k].origins);
    }
    for (int i = 0; i < m->n_pool; ++i) free(m->pool[i]);
    free(m->pool);
    for (int i = 0; i < m->n_named; ++i) free(m->named[i].values);
    free(m->per_scene);
    json_decref(m->root);
    memset(m, 0, sizeof *m);
}
