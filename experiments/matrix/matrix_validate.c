/* Checking the cells of a matrix before any runs (matrix_validate.h). */
#include "experiments/matrix/matrix_validate.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/scene/scene_load.h"
#include "experiments/driver/registry.h"
#include "experiments/run/run.h"
#include "solvers/solver.h"

/* Replaces the recorded message by "prefix: message", keeping the status. */
static int wrap_error(int status, const char *prefix)
{
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", mpm_last_error());
    mpm_clear_error();
    return mpm_error(status, "%s: %s", prefix, msg);
}

int matrix_check_solver(const char *solver, const MatrixKv *opts, int n_opts)
{
    char text[MATRIX_MAX_KV][200];
    const char *user[MATRIX_MAX_KV];
    for (int i = 0; i < n_opts; ++i) {
        snprintf(text[i], sizeof text[i], "%s=%s", opts[i].key, opts[i].value);
        user[i] = text[i];
    }
    /* the same check `run` makes before any work: spec, composition, options */
    return solver_spec_check(solver, user, n_opts);
}

static void kv_text(const MatrixKv *kv, int n, int with_origin, char *out, size_t cap)
{
    size_t len = 0;
    out[0] = '\0';
    for (int i = 0; i < n && len < cap; ++i)
        len += (size_t)snprintf(out + len, cap - len, with_origin ? "%s%s=%s (%s)" : "%s%s=%s", i ? ", " : "", kv[i].key,
                                kv[i].value, kv[i].origin);
}

/* Checked keys, kept to check each distinct combination once. */
typedef struct {
    char **keys;
    int n, cap;
} Seen;

static int seen_add(Seen *s, const char *key)
{
    for (int i = 0; i < s->n; ++i)
        if (!strcmp(s->keys[i], key)) return 0;
    if (s->n == s->cap) {
        int cap = s->cap ? 2 * s->cap : 32;
        char **k = realloc(s->keys, sizeof *k * (size_t)cap);
        if (!k) return -1;
        s->keys = k;
        s->cap = cap;
    }
    if (!(s->keys[s->n] = strdup(key))) return -1;
    s->n++;
    return 1;
}

static void seen_free(Seen *s)
{
    for (int i = 0; i < s->n; ++i) free(s->keys[i]);
    free(s->keys);
}

static int check_scene(const Matrix *m, const MatrixCell *c)
{
    for (int i = 0; i < c->n_set; ++i)
        if (strlen(c->set[i].key) + strlen(c->set[i].value) + 2 > RUN_SET_TEXT)
            return mpm_error(MPM_EINPUT, "%s: %s: set %s=%s: longer than --set takes (%d characters)", m->base,
                             c->set[i].origin, c->set[i].key, c->set[i].value, RUN_SET_TEXT - 1);
    /* the scene as the cell's run loads it */
    static MatrixCellTexts texts;
    RunConfig cfg;
    int st = matrix_cell_config(m, c, "", &cfg, &texts);
    if (st) return st;
    const char *solver_opts[RUN_MAX_LIST + 1];
    SessionConfig scfg;
    run_session_config(&cfg, &scfg, solver_opts);
    Scene sc;
    st = session_load_scene(&scfg, &sc);
    int frames = sc.frames;
    scene_free(&sc);
    char scale[32], prefix[2048];
    matrix_format_number(c->run.scale, scale, sizeof scale);
    if (st) {
        char sets[1024];
        kv_text(c->set, c->n_set, 1, sets, sizeof sets);
        snprintf(prefix, sizeof prefix, "%s: scene \"%s\" (%s) at scale %s%s%s", m->base, c->run.scene, c->origin[run_setting_index("scene")],
                 scale, c->n_set ? " with set " : "", sets);
        return wrap_error(st, prefix);
    }
    if (!c->run.frames && c->first_timed_frame >= frames)
        return mpm_error(MPM_EINPUT, "%s: scene \"%s\": first_timed_frame %d is not before the scene's %d frames",
                         m->base, c->run.scene, c->first_timed_frame, frames);
    return MPM_OK;
}

int matrix_validate_cells(const Matrix *m, const MatrixCells *cells, const int *load)
{
    Seen solvers = {0}, scenes = {0};
    int st = MPM_OK;
    for (int i = 0; i < cells->n && !st; ++i) {
        const MatrixCell *c = &cells->cells[i];
        char key[4096], opts[2048];
        kv_text(c->solver_opts, c->n_solver_opts, 0, opts, sizeof opts);
        snprintf(key, sizeof key, "%s|%s", c->run.solver, opts);
        int fresh = seen_add(&solvers, key);
        if (fresh < 0) st = mpm_error(MPM_EINTERNAL, "out of memory");
        if (fresh > 0 && (st = matrix_check_solver(c->run.solver, c->solver_opts, c->n_solver_opts))) {
            char with[2048], prefix[2600];
            kv_text(c->solver_opts, c->n_solver_opts, 1, with, sizeof with);
            snprintf(prefix, sizeof prefix, "%s: solver \"%s\" (%s)%s%s", m->base, c->run.solver, c->origin[run_setting_index("solver")],
                     c->n_solver_opts ? " with solver options " : "", with);
            st = wrap_error(st, prefix);
        }
        if (st || (load && !load[i])) continue;
        char sets[2048], scale[32], first[16];
        kv_text(c->set, c->n_set, 0, sets, sizeof sets);
        matrix_format_number(c->run.scale, scale, sizeof scale);
        snprintf(first, sizeof first, "%d", c->run.frames ? 0 : c->first_timed_frame);
        snprintf(key, sizeof key, "%s|%s|%s|%s|%s", c->run.scene, scale, sets, c->run.asset_dir ? c->run.asset_dir : "",
                 first);
        fresh = seen_add(&scenes, key);
        if (fresh < 0) st = mpm_error(MPM_EINTERNAL, "out of memory");
        if (fresh > 0) st = check_scene(m, c);
    }
    seen_free(&solvers);
    seen_free(&scenes);
    return st;
}
