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

/* One "key": value of the canonical form. */
typedef struct {
    const char *key;
    Text value;
} Entry;

static int cmp_entry(const void *a, const void *b) { return strcmp(((const Entry *)a)->key, ((const Entry *)b)->key); }

/* The value of run setting o in the cell, as canonical JSON text. */
static void setting_text(const Option *o, const MatrixCell *c, Text *t)
{
    if (o->type == OPT_LIST) {
        if (o->flags & OPT_KEY_JSON) text_kv(t, c->set, c->n_set);
        else text_kv(t, c->solver_opts, c->n_solver_opts);
        return;
    }
    OptionValue v;
    option_get(o, &c->run, &v);
    if (o->flags & OPT_KEY_SUBDIR) {
        text_add(t, v.s ? "true" : "false");
        return;
    }
    switch (o->type) {
    case OPT_SWITCH:
        text_add(t, v.i ? "true" : "false");
        break;
    case OPT_INT:
        text_int(t, v.i);
        break;
    case OPT_REAL:
        text_number(t, v.d);
        break;
    case OPT_SIZE:
        text_number(t, (double)v.z);
        break;
    case OPT_CHOICE:
        text_string(t, o->choices[v.i]);
        break;
    case OPT_TEXT:
        text_string(t, v.s ? v.s : "");
        break;
    case OPT_LIST:
        break;
    }
}

/* Does run setting k enter the cell's id? OPT_ID_ALWAYS ones do; OPT_ID_GIVEN
 * ones (added after the first results were made) only when given, a switch
 * only when on, so that the cells without them keep their ids. */
static int in_id(int k, const MatrixCell *c)
{
    const Option *o = &run_settings[k];
    if (!o->key) return 0;
    if (o->flags & OPT_ID_ALWAYS) return 1;
    if (!(o->flags & OPT_ID_GIVEN)) return 0;
    if (o->type == OPT_SWITCH) {
        OptionValue v;
        option_get(o, &c->run, &v);
        return v.i != 0;
    }
    return (int)(c->given >> k & 1);
}

/* The canonical serialisation (JSON, keys in alphabetical order, numbers as
 * the shortest text that reads back the same, so no library's number
 * formatting enters an id) and the id derived from it: the run settings of
 * the table (in_id) and the matrix's first_timed_frame, reference and repeat. */
static int cell_identify(MatrixCell *c)
{
    Entry e[RUN_SETTINGS_MAX + 4];
    int n = 0;
    for (int k = 0; k < run_settings_count; ++k) {
        if (!in_id(k, c)) continue;
        e[n].key = run_settings[k].key;
        e[n].value = (Text){NULL, 0, 0, 0};
        setting_text(&run_settings[k], c, &e[n++].value);
    }
    e[n].key = "first_timed_frame";
    e[n].value = (Text){NULL, 0, 0, 0};
    text_int(&e[n++].value, c->first_timed_frame);
    if (c->ref_id[0]) {
        e[n].key = "reference";
        e[n].value = (Text){NULL, 0, 0, 0};
        text_string(&e[n++].value, c->ref_id);
    }
    if (c->sample_frames) {
        e[n].key = "sample_frames";
        e[n].value = (Text){NULL, 0, 0, 0};
        text_string(&e[n++].value, c->sample_frames);
    }
    if (c->repeat > 1) { /* the first run keeps the id of a matrix without repeat */
        e[n].key = "repeat";
        e[n].value = (Text){NULL, 0, 0, 0};
        text_int(&e[n++].value, c->repeat);
    }
    qsort(e, (size_t)n, sizeof e[0], cmp_entry);
    Text t = {NULL, 0, 0, 0};
    text_add(&t, "{");
    for (int i = 0; i < n; ++i) {
        text_key(&t, e[i].key, i == 0);
        if (e[i].value.bad || !e[i].value.s) t.bad = 1;
        else text_add(&t, e[i].value.s);
        free(e[i].value.s);
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

/* Does the cell have the rule's value v for key (a run setting's axis, by
 * number or text, or a named axis, by label)? */
static int rule_value_matches(const Matrix *m, const MatrixCell *c, const char *key, json_t *v)
{
    int k = run_setting_index(key);
    if (k >= 0 && run_settings[k].type != OPT_TEXT) {
        OptionValue x;
        option_get(&run_settings[k], &c->run, &x);
        if (run_settings[k].type == OPT_REAL) return json_number_value(v) == x.d;
        return json_integer_value(v) == x.i;
    }
    char text[256];
    if (json_is_number(v)) matrix_format_number(json_number_value(v), text, sizeof text);
    else snprintf(text, sizeof text, "%s", json_string_value(v));
    if (k >= 0) {
        OptionValue x;
        option_get(&run_settings[k], &c->run, &x);
        return !strcmp(text, x.s ? x.s : "");
    }
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

static void apply(MatrixCell *c, int k, const OptionValue *v, const char *origin)
{
    option_set(&run_settings[k], &c->run, v);
    c->given |= 1ull << k;
    c->origin[k] = origin;
}

/* The run settings axes (table order: the scene varies slowest) and their
 * number. */
static int fixed_axes(int *setting)
{
    int n = 0;
    for (int k = 0; k < run_settings_count; ++k)
        if (run_settings[k].flags & OPT_AXIS) setting[n++] = k;
    return n;
}

/* The cell at one point of the product: idx[a] indexes the values of the
 * fixed axis a (fixed_axes; -1 = not an axis), idx[n_fixed + a] the named
 * axis a. Each run setting: the defaults' value < the scene's < the axis's.
 * Not identified yet (cell_identify). */
static int build_cell(const Matrix *m, const int *idx, MatrixCell *c)
{
    const MatrixSettings *d = &m->defaults;
    memset(c, 0, sizeof *c);
    run_config_default(&c->run);
    int fixed[RUN_SETTINGS_MAX], n_fixed = fixed_axes(fixed);
    /* the scene first: its per-scene settings apply */
    const char *scene = d->run.scene;
    for (int a = 0; a < n_fixed; ++a)
        if (fixed[a] == run_setting_index("scene") && idx[a] >= 0) scene = m->axis[fixed[a]].values[idx[a]].s;
    const MatrixSettings *ps = scene_settings(m, scene);
    for (int k = 0; k < run_settings_count; ++k) {
        if (!run_settings[k].key || run_settings[k].type == OPT_LIST) continue;
        OptionValue v;
        if (d->given >> k & 1) {
            option_get(&run_settings[k], &d->run, &v);
            apply(c, k, &v, d->origin[k]);
        }
        if (ps && (ps->given >> k & 1)) {
            option_get(&run_settings[k], &ps->run, &v);
            apply(c, k, &v, ps->origin[k]);
        }
    }
    for (int a = 0; a < n_fixed; ++a)
        if (idx[a] >= 0) apply(c, fixed[a], &m->axis[fixed[a]].values[idx[a]], m->axis[fixed[a]].origins[idx[a]]);
    c->first_timed_frame = ps && ps->has_first ? ps->first_timed_frame : d->has_first ? d->first_timed_frame : 0;
    c->timeout_s = m->cell_timeout_s;
    c->ref = -1;
    c->repeat = 1;
    MatrixKvList set = d->set, opts = d->solver_opts;
    int st = ps ? kv_merge(m, scene, &set, &ps->set) : MPM_OK;
    for (int a = 0; a < m->n_named && !st; ++a) {
        c->value[a] = idx[n_fixed + a];
        const MatrixNamedValue *v = &m->named[a].values[idx[n_fixed + a]];
        st = kv_merge(m, scene, m->named[a].kind == MATRIX_SET ? &set : &opts, &v->kv);
    }
    if (st) return st;
    if (c->run.frames > 0 && c->first_timed_frame >= c->run.frames)
        return mpm_error(MPM_EINPUT, "%s: scene \"%s\": first_timed_frame %d is not before frames %d", m->base, scene,
                         c->first_timed_frame, c->run.frames);
    st = copy_kv(&set, &c->set, &c->n_set);
    if (!st) st = copy_kv(&opts, &c->solver_opts, &c->n_solver_opts);
    for (int k = 0; k < run_settings_count; ++k) /* a list is given when it has entries */
        if (run_settings[k].type == OPT_LIST && (run_settings[k].flags & OPT_KEY_JSON ? c->n_set : c->n_solver_opts))
            c->given |= 1ull << k;
    return st;
}

/* The scene's reference run spec, or NULL. */
static const MatrixReference *scene_reference(const Matrix *m, const char *scene)
{
    const MatrixSettings *ps = scene_settings(m, scene);
    if (ps && ps->has_reference) return ps->reference.has ? &ps->reference : NULL;
    return m->reference.has ? &m->reference : NULL;
}

/* The reference cell of c: c's settings with the reference's solver, eps,
 * solver options and set overrides (on top of c's: a study of transfers
 * compares each against one of them), no error reference, writing its
 * trajectory. */
static int build_reference(const MatrixReference *r, const MatrixCell *c, MatrixCell *ref)
{
    *ref = *c;
    ref->set = ref->solver_opts = NULL;
    ref->canonical = NULL;
    ref->n_set = ref->n_solver_opts = 0;
    OptionValue v;
    v.s = r->solver;
    apply(ref, run_setting_index("solver"), &v, r->solver_origin);
    v.d = r->eps;
    apply(ref, run_setting_index("eps"), &v, r->origin);
    if (r->sample_frames) { /* checkpoints at the sampled frames, up to the last one's start */
        const char *last = strrchr(r->sample_frames, ',');
        v.i = atoi(last ? last + 1 : r->sample_frames) + 1;
        apply(ref, run_setting_index("frames"), &v, r->origin);
        ref->run.checkpoint_at = r->sample_frames;
        ref->sample_frames = r->sample_frames;
        ref->first_timed_frame = 0;
    } else {
        v.i = 1;
        apply(ref, run_setting_index("trajectory"), &v, r->origin);
    }
    ref->run.error_ref = NULL;
    ref->given &= ~(1ull << run_setting_index("error_ref"));
    ref->run.history = 0;
    ref->run.particles_dir = NULL;
    ref->is_reference = 1;
    ref->ref = -1;
    ref->ref_id[0] = '\0';
    MatrixKvList set = {.n = 0};
    for (int i = 0; i < c->n_set; ++i) set.kv[set.n++] = c->set[i];
    for (int i = 0; i < r->set.n; ++i) {
        int slot = -1;
        for (int k = 0; k < set.n; ++k)
            if (!strcmp(set.kv[k].key, r->set.kv[i].key)) slot = k;
        if (slot < 0) {
            if (set.n >= MATRIX_MAX_KV)
                return mpm_error(MPM_EINPUT, "%s: the reference run gets more than %d set entries", r->origin,
                                 MATRIX_MAX_KV);
            slot = set.n++;
        }
        set.kv[slot] = r->set.kv[i];
    }
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

/* A cell over ranks cannot do what `run` refuses over ranks
 * (docs/distributed.md): said once, when the matrix is read, not by every
 * cell's exit 2. */
static int ranks_refusal(const Matrix *m, const MatrixCell *c, const MatrixReference *r)
{
    const char *what = r                     ? "a reference run (its trajectory)"
                       : c->run.error_ref     ? "error_ref"
                       : c->run.particles_dir ? "particles"
                                              : NULL;
    if (!what) return MPM_OK;
    return mpm_error(MPM_EINPUT, "%s: scene \"%s\": ranks %d: not with %s yet (docs/distributed.md)", m->base,
                     c->run.scene, c->run.ranks, what);
}

int matrix_expand(const Matrix *m, MatrixCells *out)
{
    memset(out, 0, sizeof *out);
    int fixed[RUN_SETTINGS_MAX], n_fixed = fixed_axes(fixed);
    int n_axes = n_fixed + m->n_named;
    int size[RUN_SETTINGS_MAX + MATRIX_MAX_AXES];
    for (int a = 0; a < n_fixed; ++a) size[a] = m->axis[fixed[a]].n;
    for (int a = 0; a < m->n_named; ++a) size[n_fixed + a] = m->named[a].n;
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
    int idx[RUN_SETTINGS_MAX + MATRIX_MAX_AXES];
    for (int a = 0; a < n_axes; ++a) idx[a] = size[a] > 0 ? 0 : -1;
    int st = MPM_OK;
    for (size_t k = 0; k < total && !st; ++k) {
        MatrixCell *c = &out->cells[out->n];
        st = build_cell(m, idx, c);
        int keep = !st && rules_keep(m, c);
        const MatrixReference *r = keep ? scene_reference(m, c->run.scene) : NULL;
        if (keep && c->run.ranks > 1) st = ranks_refusal(m, c, r);
        if (r && !st) { /* the reference first: its id is part of the cell's settings */
            MatrixCell *rc = &refs[n_refs];
            st = build_reference(r, c, rc);
            int j = st ? -1 : find_same(refs, n_refs, rc);
            if (j == -2) st = MPM_EINTERNAL;
            if (!st) snprintf(c->ref_id, sizeof c->ref_id, "%s", rc->id);
            if (!st && r->sample_frames) { /* the cell times the reference's checkpoints */
                if (c->first_timed_frame > 0)
                    st = mpm_error(MPM_EINPUT, "%s: %s.sample_frames: not with first_timed_frame %d (every sampled "
                                               "frame is timed)",
                                   m->base, r->origin, c->first_timed_frame);
                c->sample_frames = r->sample_frames;
            }
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

void matrix_cell_name(const MatrixCell *c, char *out, size_t n) { snprintf(out, n, "%s/%s", c->run.scene, c->run.solver); }

void matrix_cell_describe(const Matrix *m, const MatrixCell *c, char *out, size_t n)
{
    char eps[32], scale[32];
    matrix_format_number(c->run.eps, eps, sizeof eps);
    matrix_format_number(c->run.scale, scale, sizeof scale);
    size_t len = (size_t)snprintf(out, n, "eps=%s scale=%s", eps, scale);
    if (c->run.threads && len < n) len += (size_t)snprintf(out + len, n - len, " threads=%d", c->run.threads);
    if (c->run.ranks && len < n) len += (size_t)snprintf(out + len, n - len, " ranks=%d", c->run.ranks);
    if (c->run.frames && !(c->sample_frames && !c->is_reference) && len < n)
        len += (size_t)snprintf(out + len, n - len, " frames=%d", c->run.frames);
    if (c->first_timed_frame && len < n) len += (size_t)snprintf(out + len, n - len, " timed-from=%d", c->first_timed_frame);
    if (c->run.error_ref && len < n) len += (size_t)snprintf(out + len, n - len, " error_ref=%s", c->run.error_ref);
    for (int a = 0; a < m->n_named && len < n; ++a)
        len += (size_t)snprintf(out + len, n - len, " %s=%s", m->named[a].name, m->named[a].values[c->value[a]].label);
    if (c->repeat > 1 && len < n) len += (size_t)snprintf(out + len, n - len, " repeat=%d", c->repeat);
    if (c->sample_frames && len < n)
        len += (size_t)snprintf(out + len, n - len, c->is_reference ? " checkpoints=%s" : " sampled=%s", c->sample_frames);
    if (c->is_reference && len < n) len += (size_t)snprintf(out + len, n - len, " (reference run)");
    else if (c->ref_id[0] && len < n) len += (size_t)snprintf(out + len, n - len, " reference=%s", c->ref_id);
}

int matrix_cell_config(const Matrix *m, const MatrixCell *c, const char *out_dir, RunConfig *cfg,
                       MatrixCellTexts *texts)
{
    *cfg = c->run;
    matrix_scene_path(m, c->run.scene, texts->scene, sizeof texts->scene);
    cfg->scene = texts->scene;
    int w = 0;
    if (c->run.particles_dir) {
        w = snprintf(texts->particles, sizeof texts->particles, "%s/%s", out_dir, c->run.particles_dir);
        if (w < 0 || (size_t)w >= sizeof texts->particles) return mpm_error(MPM_EINPUT, "cell command line too long");
        cfg->particles_dir = texts->particles;
    }
    cfg->n_set = cfg->n_solver_opts = 0;
    for (int i = 0; i < c->n_set && i < RUN_MAX_LIST; ++i) {
        snprintf(texts->set[i], sizeof texts->set[i], "%s=%s", c->set[i].key, c->set[i].value);
        cfg->set[cfg->n_set++] = texts->set[i];
    }
    for (int i = 0; i < c->n_solver_opts && i < RUN_MAX_LIST; ++i) {
        snprintf(texts->solver_opts[i], sizeof texts->solver_opts[i], "%s=%s", c->solver_opts[i].key,
                 c->solver_opts[i].value);
        cfg->solver_opts[cfg->n_solver_opts++] = texts->solver_opts[i];
    }
    if (c->ref_id[0]) { /* the reference's directory: out_dir's sibling */
        const char *slash = strrchr(out_dir, '/');
        w = slash ? snprintf(texts->reference, sizeof texts->reference, "%.*s/%s", (int)(slash - out_dir), out_dir,
                             c->ref_id)
                  : snprintf(texts->reference, sizeof texts->reference, "%s", c->ref_id);
        if (w < 0 || (size_t)w >= sizeof texts->reference) return mpm_error(MPM_EINPUT, "cell command line too long");
        if (c->sample_frames) { /* the reference's checkpoints, each sampled frame alone */
            size_t len = strlen(texts->reference);
            if (len + sizeof "/checkpoints" > sizeof texts->reference)
                return mpm_error(MPM_EINPUT, "cell command line too long");
            memcpy(texts->reference + len, "/checkpoints", sizeof "/checkpoints");
            cfg->sample_from = texts->reference;
            cfg->sample_frames = c->sample_frames;
            cfg->frames = 0;
        } else {
            cfg->dt_from = cfg->trajectory_ref = texts->reference;
        }
    }
    cfg->quiet = 1;
    cfg->out_dir = out_dir;
    return MPM_OK;
}

int matrix_cell_argv(const Matrix *m, const MatrixCell *c, const char *out_dir, char *buf, size_t cap, int *argc)
{
    MatrixCellTexts *texts = malloc(sizeof *texts); /* 30 kB: not on the stack */
    if (!texts) return mpm_error(MPM_EINTERNAL, "out of memory");
    RunConfig cfg;
    int st = matrix_cell_config(m, c, out_dir, &cfg, texts);
    if (!st) st = run_config_argv(&cfg, buf, cap, argc);
    free(texts);
    return st;
}
