/* Cells of an experiment matrix: expansion, ids, command lines
 * (matrix_cells.h). */
#include "experiments/matrix/matrix_cells.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* src on top of dst (src wins); MPM_EINPUT past MATRIX_MAX_KV keys. */
static int kv_merge(const Matrix *m, const char *scene, MatrixKvList *dst, const MatrixKvList *src)
{
    for (int i = 0; i < src->n; ++i) {
        int slot = -1;
        for (int k = 0; k < dst->n; ++k)
            if (!strcmp(dst->kv[k].key, src->kv[i].key)) slot = k;
        if (slot < 0) {
            if (dst->n >= MATRIX_MAX_KV)
                return mpm_error(MPM_EINPUT, "%s: %s: a cell of scene \"%s\" gets more than %d set/solver_opts entries",
                                 m->base, src->kv[i].origin, scene, MATRIX_MAX_KV);
            slot = dst->n++;
        }
        dst->kv[slot] = src->kv[i];
    }
    return MPM_OK;
}

static int cmp_kv(const void *a, const void *b) { return strcmp(((const MatrixKv *)a)->key, ((const MatrixKv *)b)->key); }

/* FNV-1a, 64 bits (offset basis 0xcbf29ce484222325, prime 0x100000001b3). */
static uint64_t fnv1a64(const char *s)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    for (; *s; ++s) {
        h ^= (unsigned char)*s;
        h *= 0x100000001b3ULL;
    }
    return h;
}

/* Growing text buffer for the canonical form. */
typedef struct {
    char *s;
    size_t len, cap;
    int bad;
} Text;

static void text_add(Text *t, const char *s)
{
    size_t n = strlen(s);
    if (t->bad) return;
    if (t->len + n + 1 > t->cap) {
        size_t cap = 2 * (t->len + n + 1) + 256;
        char *p = realloc(t->s, cap);
        if (!p) {
            t->bad = 1;
            return;
        }
        t->s = p;
        t->cap = cap;
    }
    memcpy(t->s + t->len, s, n + 1);
    t->len += n;
}

/* A JSON string literal (jansson's escaping). */
static void text_string(Text *t, const char *s)
{
    json_t *j = json_string(s);
    char *q = j ? json_dumps(j, JSON_ENCODE_ANY) : NULL;
    if (q) text_add(t, q);
    else t->bad = 1;
    free(q);
    json_decref(j);
}

static void text_key(Text *t, const char *key, int first)
{
    if (!first) text_add(t, ",");
    text_string(t, key);
    text_add(t, ":");
}

static void text_number(Text *t, double v)
{
    char num[64];
    matrix_format_number(v, num, sizeof num);
    text_add(t, num);
}

static void text_int(Text *t, int v)
{
    char num[32];
    snprintf(num, sizeof num, "%d", v);
    text_add(t, num);
}

static void text_kv(Text *t, const MatrixKv *kv, int n)
{
    text_add(t, "{");
    for (int i = 0; i < n; ++i) { /* sorted by key */
        text_key(t, kv[i].key, i == 0);
        text_string(t, kv[i].value);
    }
    text_add(t, "}");
}

/* The canonical serialisation (JSON, keys in alphabetical order, numbers as
 * the shortest text that reads back the same, so no library's number
 * formatting enters an id) and the id derived from it. */
static int cell_identify(MatrixCell *c)
{
    Text t = {NULL, 0, 0, 0};
    /* the settings added with the accuracy axis and the limits enter only when
     * set, so the ids of cells without them stay as they were */
    text_add(&t, "{");
    text_key(&t, "armijo", 1);
    text_add(&t, c->armijo ? "true" : "false");
    text_key(&t, "eps", 0);
    text_number(&t, c->eps);
    if (c->error_ref[0]) {
        text_key(&t, "error_ref", 0);
        text_string(&t, c->error_ref);
    }
    text_key(&t, "first_timed_frame", 0);
    text_int(&t, c->first_timed_frame);
    text_key(&t, "frames", 0);
    text_int(&t, c->frames);
    text_key(&t, "history", 0);
    text_add(&t, c->history ? "true" : "false");
    if (c->max_linear) {
        text_key(&t, "max_linear", 0);
        text_int(&t, c->max_linear);
    }
    if (c->max_outer) {
        text_key(&t, "max_outer", 0);
        text_int(&t, c->max_outer);
    }
    if (c->max_run_s > 0) {
        text_key(&t, "max_run_seconds", 0);
        text_number(&t, c->max_run_s);
    }
    if (c->max_step_s > 0) {
        text_key(&t, "max_step_seconds", 0);
        text_number(&t, c->max_step_s);
    }
    if (c->on_failure[0]) {
        text_key(&t, "on_failure", 0);
        text_string(&t, c->on_failure);
    }
    text_key(&t, "particles", 0);
    text_add(&t, c->particles ? "true" : "false");
    if (c->ref_id[0]) {
        text_key(&t, "reference", 0);
        text_string(&t, c->ref_id);
    }
    if (c->repeat > 1) { /* the first run keeps the id of a matrix without repeat */
        text_key(&t, "repeat", 0);
        text_int(&t, c->repeat);
    }
    text_key(&t, "scale", 0);
    text_number(&t, c->scale);
    text_key(&t, "scene", 0);
    text_string(&t, c->scene);
    text_key(&t, "set", 0);
    text_kv(&t, c->set, c->n_set);
    text_key(&t, "solver", 0);
    text_string(&t, c->solver);
    text_key(&t, "solver_opts", 0);
    text_kv(&t, c->solver_opts, c->n_solver_opts);
    text_key(&t, "threads", 0);
    text_int(&t, c->threads);
    if (c->trajectory) {
        text_key(&t, "trajectory", 0);
        text_add(&t, "true");
    }
    text_add(&t, "}");
    if (t.bad) {
        free(t.s);
        return mpm_error(MPM_EINTERNAL, "out of memory (cell settings)");
    }
    c->canonical = t.s;
    snprintf(c->id, sizeof c->id, "%012llx", (unsigned long long)(fnv1a64(c->canonical) & 0xffffffffffffULL));
    return MPM_OK;
}

/* The cell's value of a rule key as text (string axes, labels) or number. */
static int rule_value_matches(const Matrix *m, const MatrixCell *c, const char *key, json_t *v)
{
    if (!strcmp(key, "eps")) return json_number_value(v) == c->eps;
    if (!strcmp(key, "scale")) return json_number_value(v) == c->scale;
    if (!strcmp(key, "threads")) return json_integer_value(v) == c->threads;
    char text[256];
    if (json_is_number(v)) matrix_format_number(json_number_value(v), text, sizeof text);
    else snprintf(text, sizeof text, "%s", json_string_value(v));
    if (!strcmp(key, "scene")) return !strcmp(text, c->scene);
    if (!strcmp(key, "solver")) return !strcmp(text, c->solver);
    if (!strcmp(key, "error_ref")) return !strcmp(text, c->error_ref);
    int a = matrix_named_index(m, key);
    return a >= 0 && !strcmp(text, m->named[a].values[c->value[a]].label);
}

static int rule_matches(const Matrix *m, const MatrixCell *c, json_t *rule)
{
    const char *key;
    json_t *v;
    json_object_foreach(rule, key, v) {
        int any = 0;
        if (json_is_array(v)) {
            for (size_t i = 0; i < json_array_size(v) && !any; ++i) any = rule_value_matches(m, c, key, json_array_get(v, i));
        } else {
            any = rule_value_matches(m, c, key, v);
        }
        if (!any) return 0;
    }
    return 1;
}

static int rules_keep(const Matrix *m, const MatrixCell *c)
{
    if (m->include) {
        int any = 0;
        for (size_t i = 0; i < json_array_size(m->include) && !any; ++i) any = rule_matches(m, c, json_array_get(m->include, i));
        if (!any) return 0;
    }
    if (m->exclude)
        for (size_t i = 0; i < json_array_size(m->exclude); ++i)
            if (rule_matches(m, c, json_array_get(m->exclude, i))) return 0;
    return 1;
}

static const MatrixSettings *scene_settings(const Matrix *m, const char *scene)
{
    for (int i = 0; i < m->n_per_scene; ++i)
        if (!strcmp(m->per_scene[i].scene, scene)) return &m->per_scene[i].s;
    return NULL;
}

static int copy_kv(const MatrixKvList *l, MatrixKv **out, int *n)
{
    *n = l->n;
    *out = NULL;
    if (!l->n) return MPM_OK;
    if (!(*out = malloc(sizeof **out * (size_t)l->n))) return mpm_error(MPM_EINTERNAL, "out of memory");
    memcpy(*out, l->kv, sizeof **out * (size_t)l->n);
    qsort(*out, (size_t)l->n, sizeof **out, cmp_kv);
    return MPM_OK;
}

/* The run limits and error reference: defaults < per-scene settings. */
static void run_settings(const MatrixSettings *d, const MatrixSettings *ps, MatrixCell *c)
{
    const MatrixSettings *src[2] = {d, ps};
    for (int k = 0; k < 2; ++k) {
        const MatrixSettings *s = src[k];
        if (!s) continue;
        if (s->has_error_ref) snprintf(c->error_ref, sizeof c->error_ref, "%s", s->error_ref);
        if (s->has_trajectory) c->trajectory = s->trajectory;
        if (s->has_max_outer) c->max_outer = s->max_outer;
        if (s->has_max_linear) c->max_linear = s->max_linear;
        if (s->has_max_step_s) c->max_step_s = s->max_step_s;
        if (s->has_max_run_s) c->max_run_s = s->max_run_s;
        if (s->has_on_failure) snprintf(c->on_failure, sizeof c->on_failure, "%s", s->on_failure);
    }
}

#define FIXED_AXES 6 /* scene, solver, eps, scale, threads, error_ref */

/* The cell at one point of the product: idx[0..5] index scene, solver, eps,
 * scale, threads, error_ref (-1 = the defaults' value), idx[FIXED_AXES+a]
 * the named axis a. Not identified yet (cell_identify). */
static int build_cell(const Matrix *m, const int *idx, MatrixCell *c)
{
    const MatrixSettings *d = &m->defaults;
    memset(c, 0, sizeof *c);
    snprintf(c->scene, sizeof c->scene, "%s", idx[0] >= 0 ? m->scenes[idx[0]] : d->scene);
    if (idx[0] >= 0) snprintf(c->scene_origin, sizeof c->scene_origin, "axes.scene[%d]", idx[0]);
    else snprintf(c->scene_origin, sizeof c->scene_origin, "%s", d->scene_origin);
    snprintf(c->solver, sizeof c->solver, "%s", idx[1] >= 0 ? m->solvers[idx[1]] : d->solver);
    if (idx[1] >= 0) snprintf(c->solver_origin, sizeof c->solver_origin, "axes.solver[%d]", idx[1]);
    else snprintf(c->solver_origin, sizeof c->solver_origin, "%s", d->solver_origin);
    const MatrixSettings *ps = scene_settings(m, c->scene);
    c->eps = d->has_eps ? d->eps : 1e-7;
    c->scale = ps && ps->has_scale ? ps->scale : d->has_scale ? d->scale : 1.0;
    c->threads = d->has_threads ? d->threads : 0;
    c->frames = ps && ps->has_frames ? ps->frames : d->has_frames ? d->frames : 0;
    c->first_timed_frame = ps && ps->has_first ? ps->first_timed_frame : d->has_first ? d->first_timed_frame : 0;
    if (idx[2] >= 0) c->eps = m->eps[idx[2]];
    if (idx[3] >= 0) c->scale = m->scales[idx[3]];
    if (idx[4] >= 0) c->threads = m->threads[idx[4]];
    c->history = d->history;
    c->armijo = d->armijo;
    c->particles = d->particles;
    snprintf(c->asset_dir, sizeof c->asset_dir, "%s", d->has_asset_dir ? d->asset_dir : "");
    c->timeout_s = m->cell_timeout_s;
    c->ref = -1;
    c->repeat = 1;
    run_settings(d, ps, c);
    if (idx[5] >= 0) snprintf(c->error_ref, sizeof c->error_ref, "%s", m->error_refs[idx[5]]);
    MatrixKvList set = d->set, opts = d->solver_opts;
    int st = ps ? kv_merge(m, c->scene, &set, &ps->set) : MPM_OK;
    for (int a = 0; a < m->n_named && !st; ++a) {
        c->value[a] = idx[FIXED_AXES + a];
        const MatrixNamedValue *v = &m->named[a].values[idx[FIXED_AXES + a]];
        st = kv_merge(m, c->scene, m->named[a].kind == MATRIX_SET ? &set : &opts, &v->kv);
    }
    if (st) return st;
    if (c->frames > 0 && c->first_timed_frame >= c->frames)
        return mpm_error(MPM_EINPUT, "%s: scene \"%s\": first_timed_frame %d is not before frames %d", m->base, c->scene,
                         c->first_timed_frame, c->frames);
    st = copy_kv(&set, &c->set, &c->n_set);
    if (!st) st = copy_kv(&opts, &c->solver_opts, &c->n_solver_opts);
    return st;
}

/* The scene's reference run spec, or NULL. */
static const MatrixReference *scene_reference(const Matrix *m, const char *scene)
{
    const MatrixSettings *ps = scene_settings(m, scene);
    if (ps && ps->has_reference) return ps->reference.has ? &ps->reference : NULL;
    return m->reference.has ? &m->reference : NULL;
}

/* The reference cell of c: c's settings with the reference's solver, eps and
 * solver options, no error reference, writing its trajectory. */
static int build_reference(const MatrixReference *r, const MatrixCell *c, MatrixCell *ref)
{
    *ref = *c;
    ref->set = ref->solver_opts = NULL;
    ref->canonical = NULL;
    ref->n_set = ref->n_solver_opts = 0;
    snprintf(ref->solver, sizeof ref->solver, "%s", r->solver);
    snprintf(ref->solver_origin, sizeof ref->solver_origin, "%s.solver", r->origin);
    ref->eps = r->eps;
    ref->error_ref[0] = '\0';
    ref->trajectory = 1;
    ref->history = ref->particles = 0;
    ref->is_reference = 1;
    ref->ref = -1;
    ref->ref_id[0] = '\0';
    MatrixKvList set = {.n = 0};
    for (int i = 0; i < c->n_set; ++i) set.kv[set.n++] = c->set[i];
    int st = copy_kv(&set, &ref->set, &ref->n_set);
    if (!st) st = copy_kv(&r->solver_opts, &ref->solver_opts, &ref->n_solver_opts);
    if (!st) st = cell_identify(ref);
    return st;
}

static void cell_release(MatrixCell *c)
{
    free(c->set);
    free(c->solver_opts);
    free(c->canonical);
    memset(c, 0, sizeof *c);
}

/* Index of the cell with c's id among cells[0..n), -1 when none;
 * MPM_EINTERNAL (as -2) when the id names other settings. */
static int find_same(const MatrixCell *cells, int n, const MatrixCell *c)
{
    for (int j = 0; j < n; ++j) {
        if (strcmp(cells[j].id, c->id)) continue;
        if (strcmp(cells[j].canonical, c->canonical)) {
            mpm_error(MPM_EINTERNAL, "cell id %s names two different settings: %s and %s", c->id, cells[j].canonical,
                      c->canonical);
            return -2;
        }
        return j;
    }
    return -1;
}

/* Puts the reference cells first and points every dependent cell at its own. */
static int prepend_references(MatrixCells *out, MatrixCell *refs, int n_refs)
{
    if (!n_refs) return MPM_OK;
    MatrixCell *all = calloc((size_t)(out->n + n_refs), sizeof *all);
    if (!all) return mpm_error(MPM_EINTERNAL, "out of memory (%d cells)", out->n + n_refs);
    memcpy(all, refs, sizeof *all * (size_t)n_refs);
    if (out->n) memcpy(all + n_refs, out->cells, sizeof *all * (size_t)out->n);
    free(out->cells);
    out->cells = all;
    out->n += n_refs;
    for (int i = n_refs; i < out->n; ++i)
        for (int j = 0; j < n_refs && out->cells[i].ref_id[0]; ++j)
            if (!strcmp(out->cells[j].id, out->cells[i].ref_id)) out->cells[i].ref = j;
    return MPM_OK;
}

/* Appends repetitions 2..n of every cell that is not a reference run. */
static int add_repeats(MatrixCells *out, int n)
{
    if (n <= 1) return MPM_OK;
    int base = out->n, per = 0;
    for (int i = 0; i < base; ++i) per += !out->cells[i].is_reference;
    MatrixCell *all = realloc(out->cells, sizeof *all * (size_t)(base + per * (n - 1) + 1));
    if (!all) return mpm_error(MPM_EINTERNAL, "out of memory (%d cells x %d repeats)", per, n);
    out->cells = all;
    for (int k = 2; k <= n; ++k)
        for (int i = 0; i < base; ++i) {
            if (all[i].is_reference) continue;
            MatrixCell *c = &all[out->n];
            *c = all[i];
            c->set = c->solver_opts = NULL;
            c->canonical = NULL;
            c->repeat = k;
            MatrixKvList l = {.n = 0};
            for (int j = 0; j < all[i].n_set; ++j) l.kv[l.n++] = all[i].set[j];
            int st = copy_kv(&l, &c->set, &c->n_set);
            l.n = 0;
            for (int j = 0; j < all[i].n_solver_opts; ++j) l.kv[l.n++] = all[i].solver_opts[j];
            if (!st) st = copy_kv(&l, &c->solver_opts, &c->n_solver_opts);
            if (!st) st = cell_identify(c);
            if (st) {
                cell_release(c);
                return st;
            }
            out->n++;
        }
    return MPM_OK;
}

int matrix_expand(const Matrix *m, MatrixCells *out)
{
    memset(out, 0, sizeof *out);
    int n_axes = FIXED_AXES + m->n_named;
    int size[FIXED_AXES + MATRIX_MAX_AXES];
    size[0] = m->n_scenes;
    size[1] = m->n_solvers;
    size[2] = m->n_eps;
    size[3] = m->n_scales;
    size[4] = m->n_threads;
    size[5] = m->n_error_refs;
    for (int a = 0; a < m->n_named; ++a) size[FIXED_AXES + a] = m->named[a].n;
    size_t total = 1;
    for (int a = 0; a < n_axes; ++a) {
        total *= (size_t)(size[a] > 0 ? size[a] : 1);
        if (total > 1000000) return mpm_error(MPM_EINPUT, "%s: more than a million cells", m->base);
    }
    out->cells = calloc(total, sizeof *out->cells);
    MatrixCell *refs = calloc(total, sizeof *refs);
    int n_refs = 0;
    if (!out->cells || !refs) {
        free(refs);
        return mpm_error(MPM_EINTERNAL, "out of memory (%zu cells)", total);
    }
    int idx[FIXED_AXES + MATRIX_MAX_AXES];
    for (int a = 0; a < n_axes; ++a) idx[a] = size[a] > 0 ? 0 : -1;
    int st = MPM_OK;
    for (size_t k = 0; k < total && !st; ++k) {
        MatrixCell *c = &out->cells[out->n];
        st = build_cell(m, idx, c);
        int keep = !st && rules_keep(m, c);
        const MatrixReference *r = keep ? scene_reference(m, c->scene) : NULL;
        if (r) { /* the reference first: its id is part of the cell's settings */
            MatrixCell *rc = &refs[n_refs];
            st = build_reference(r, c, rc);
            int j = st ? -1 : find_same(refs, n_refs, rc);
            if (j == -2) st = MPM_EINTERNAL;
            if (!st) snprintf(c->ref_id, sizeof c->ref_id, "%s", rc->id);
            if (!st && j < 0) n_refs++;
            else cell_release(rc);
        }
        if (!st && keep) st = cell_identify(c);
        int j = !st && keep ? find_same(out->cells, out->n, c) : -1;
        if (j == -2) st = MPM_EINTERNAL;
        if (j >= 0) keep = 0; /* identical effective settings run once */
        if (!st && keep) out->n++;
        else cell_release(c);
        /* odometer: the last axis varies fastest */
        for (int a = n_axes - 1; a >= 0; --a) {
            if (size[a] <= 1) continue;
            if (++idx[a] < size[a]) break;
            idx[a] = 0;
        }
    }
    if (!st) {
        st = prepend_references(out, refs, n_refs);
        if (!st) st = add_repeats(out, m->repeat);
    } else {
        for (int i = 0; i < n_refs; ++i) cell_release(&refs[i]);
    }
    free(refs);
    return st;
}

void matrix_cells_free(MatrixCells *c)
{
    for (int i = 0; i < c->n; ++i) cell_release(&c->cells[i]);
    free(c->cells);
    memset(c, 0, sizeof *c);
}

void matrix_cells_keep(MatrixCells *c, const int *keep)
{
    int k = 0;
    int *moved = malloc(sizeof(int) * (size_t)(c->n + 1));
    for (int i = 0; i < c->n; ++i) {
        if (moved) moved[i] = keep[i] ? k : -1;
        if (keep[i]) c->cells[k++] = c->cells[i];
        else cell_release(&c->cells[i]);
    }
    c->n = k;
    for (int i = 0; i < k; ++i)
        if (c->cells[i].ref >= 0) c->cells[i].ref = moved ? moved[c->cells[i].ref] : -1;
    free(moved);
}

void matrix_cell_name(const MatrixCell *c, char *out, size_t n) { snprintf(out, n, "%s/%s", c->scene, c->solver); }

void matrix_cell_describe(const Matrix *m, const MatrixCell *c, char *out, size_t n)
{
    char eps[32], scale[32];
    matrix_format_number(c->eps, eps, sizeof eps);
    matrix_format_number(c->scale, scale, sizeof scale);
    size_t len = (size_t)snprintf(out, n, "eps=%s scale=%s", eps, scale);
    if (c->threads && len < n) len += (size_t)snprintf(out + len, n - len, " threads=%d", c->threads);
    if (c->frames && len < n) len += (size_t)snprintf(out + len, n - len, " frames=%d", c->frames);
    if (c->first_timed_frame && len < n) len += (size_t)snprintf(out + len, n - len, " timed-from=%d", c->first_timed_frame);
    if (c->error_ref[0] && len < n) len += (size_t)snprintf(out + len, n - len, " error_ref=%s", c->error_ref);
    for (int a = 0; a < m->n_named && len < n; ++a)
        len += (size_t)snprintf(out + len, n - len, " %s=%s", m->named[a].name, m->named[a].values[c->value[a]].label);
    if (c->repeat > 1 && len < n) len += (size_t)snprintf(out + len, n - len, " repeat=%d", c->repeat);
    if (c->is_reference && len < n) len += (size_t)snprintf(out + len, n - len, " (reference run)");
    else if (c->ref_id[0] && len < n) len += (size_t)snprintf(out + len, n - len, " reference=%s", c->ref_id);
}

/* Appends one NUL-terminated argument. */
static int push_arg(char *buf, size_t cap, size_t *used, int *argc, const char *fmt, const char *a, const char *b)
{
    int w = snprintf(buf + *used, cap - *used, fmt, a, b);
    if (w < 0 || (size_t)w + 1 > cap - *used) return mpm_error(MPM_EINPUT, "cell command line too long");
    *used += (size_t)w + 1;
    (*argc)++;
    return MPM_OK;
}

int matrix_cell_argv(const Matrix *m, const MatrixCell *c, const char *out_dir, char *buf, size_t cap, int *argc)
{
    size_t used = 0;
    *argc = 0;
    char path[2048], num[64], ply[1100];
    matrix_scene_path(m, c->scene, path, sizeof path);
    int st = push_arg(buf, cap, &used, argc, "%s%s", "run", "");
    st |= push_arg(buf, cap, &used, argc, "%s%s", "--scene", "");
    st |= push_arg(buf, cap, &used, argc, "%s%s", path, "");
    st |= push_arg(buf, cap, &used, argc, "%s%s", "--solver", "");
    st |= push_arg(buf, cap, &used, argc, "%s%s", c->solver, "");
    matrix_format_number(c->eps, num, sizeof num); /* reads back as the same double */
    st |= push_arg(buf, cap, &used, argc, "%s%s", "--eps", "");
    st |= push_arg(buf, cap, &used, argc, "%s%s", num, "");
    matrix_format_number(c->scale, num, sizeof num);
    st |= push_arg(buf, cap, &used, argc, "%s%s", "--scale", "");
    st |= push_arg(buf, cap, &used, argc, "%s%s", num, "");
    if (c->threads) {
        snprintf(num, sizeof num, "%d", c->threads);
        st |= push_arg(buf, cap, &used, argc, "%s%s", "--threads", "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", num, "");
    }
    if (c->frames) {
        snprintf(num, sizeof num, "%d", c->frames);
        st |= push_arg(buf, cap, &used, argc, "%s%s", "--frames", "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", num, "");
    }
    for (int i = 0; i < c->n_set; ++i) {
        st |= push_arg(buf, cap, &used, argc, "%s%s", "--set", "");
        st |= push_arg(buf, cap, &used, argc, "%s=%s", c->set[i].key, c->set[i].value);
    }
    for (int i = 0; i < c->n_solver_opts; ++i) {
        st |= push_arg(buf, cap, &used, argc, "%s%s", "--solver-opt", "");
        st |= push_arg(buf, cap, &used, argc, "%s=%s", c->solver_opts[i].key, c->solver_opts[i].value);
    }
    if (c->history) st |= push_arg(buf, cap, &used, argc, "%s%s", "--history", "");
    if (c->armijo) st |= push_arg(buf, cap, &used, argc, "%s%s", "--armijo", "");
    if (c->particles) {
        snprintf(ply, sizeof ply, "%s/particles", out_dir);
        st |= push_arg(buf, cap, &used, argc, "%s%s", "--particles", "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", ply, "");
    }
    if (c->asset_dir[0]) {
        st |= push_arg(buf, cap, &used, argc, "%s%s", "--asset-dir", "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", c->asset_dir, "");
    }
    if (c->error_ref[0]) {
        st |= push_arg(buf, cap, &used, argc, "%s%s", "--error-ref", "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", c->error_ref, "");
    }
    if (c->trajectory) st |= push_arg(buf, cap, &used, argc, "%s%s", "--trajectory", "");
    const int ints[2] = {c->max_outer, c->max_linear};
    const char *int_flags[2] = {"--max-outer", "--max-linear"};
    for (int k = 0; k < 2; ++k) {
        if (!ints[k]) continue;
        snprintf(num, sizeof num, "%d", ints[k]);
        st |= push_arg(buf, cap, &used, argc, "%s%s", int_flags[k], "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", num, "");
    }
    const double secs[2] = {c->max_step_s, c->max_run_s};
    const char *sec_flags[2] = {"--max-step-seconds", "--max-run-seconds"};
    for (int k = 0; k < 2; ++k) {
        if (!(secs[k] > 0)) continue;
        if (secs[k] == floor(secs[k])) snprintf(num, sizeof num, "%.0f", secs[k]); /* 30, not 3e+01 */
        else matrix_format_number(secs[k], num, sizeof num);
        st |= push_arg(buf, cap, &used, argc, "%s%s", sec_flags[k], "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", num, "");
    }
    if (c->on_failure[0]) {
        st |= push_arg(buf, cap, &used, argc, "%s%s", "--on-failure", "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", c->on_failure, "");
    }
    if (c->ref_id[0]) { /* the reference's directory: out_dir's sibling */
        const char *slash = strrchr(out_dir, '/');
        int w = slash ? snprintf(ply, sizeof ply, "%.*s/%s", (int)(slash - out_dir), out_dir, c->ref_id)
                      : snprintf(ply, sizeof ply, "%s", c->ref_id);
        if (w < 0 || (size_t)w >= sizeof ply) st |= mpm_error(MPM_EINPUT, "cell command line too long");
        st |= push_arg(buf, cap, &used, argc, "%s%s", "--dt-from", "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", ply, "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", "--trajectory-ref", "");
        st |= push_arg(buf, cap, &used, argc, "%s%s", ply, "");
    }
    st |= push_arg(buf, cap, &used, argc, "%s%s", "--quiet", "");
    st |= push_arg(buf, cap, &used, argc, "%s%s", "--out", "");
    st |= push_arg(buf, cap, &used, argc, "%s%s", out_dir, "");
    return st ? MPM_EINPUT : MPM_OK;
}
