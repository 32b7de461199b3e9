#include "experiments/matrix/matrix_run.h"

#include <fnmatch.h>
#include <jansson.h>
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/event_log.h"
#include "core/error.h"
#include "experiments/matrix/matrix_cells.h"
#include "experiments/matrix/matrix_check.h"
#include "experiments/matrix/matrix_child.h"
#include "experiments/matrix/matrix_dispatch.h"
#include "experiments/matrix/matrix_file.h"
#include "experiments/matrix/matrix_results.h"
#include "experiments/io/mpi_launcher.h"
#include "experiments/io/paths.h"
#include "experiments/matrix/matrix_resume.h"
#include "experiments/matrix/matrix_validate.h"
#include "experiments/run/provenance.h"

typedef struct {
    Matrix m;
    MatrixCells cells;
    CellsFile results;
    char dir[1024];
    int *todo;             /* cell indices to run, in dispatch order */
    int n_todo, n_done_before, n_finished, n_skipped, n_busy;
    int n_status[CELL_N_STATUS];
    double t_start, last_tick;
    int terminal, tick_shown;
    double checkpoint_every_s; /* a checkpoint reference's resume checkpoints (matrix_resume.h) */
} Run;

static int matches_only(const MatrixCell *c, const MatrixRunOptions *o)
{
    if (!o->n_only) return 1;
    char name[1200];
    matrix_cell_name(c, name, sizeof name);
    for (int i = 0; i < o->n_only; ++i)
        if (!fnmatch(o->only[i], c->id, 0) || !fnmatch(o->only[i], name, 0)) return 1;
    return 0;
}

/* Keeps the cells --only selects (all without --only). */
static int select_cells(Run *r, const MatrixRunOptions *o)
{
    if (!o->n_only) return MPM_OK;
    int *keep = calloc((size_t)r->cells.n + 1, sizeof *keep);
    if (!keep) return mpm_error(MPM_EINTERNAL, "out of memory");
    for (int i = 0; i < r->cells.n; ++i) keep[i] = matches_only(&r->cells.cells[i], o);
    for (int i = 0; i < r->cells.n; ++i) /* a selected cell needs its reference run */
        if (keep[i] && r->cells.cells[i].ref >= 0) keep[r->cells.cells[i].ref] = 1;
    matrix_cells_keep(&r->cells, keep);
    free(keep);
    if (!r->cells.n) return mpm_error(MPM_EINPUT, "--only %s: no cell of %s matches", o->only[0], r->m.base);
    return MPM_OK;
}

static json_t *named_axes_json(const Matrix *m)
{
    json_t *axes = json_array();
    for (int a = 0; a < m->n_named; ++a) {
        json_t *values = json_array();
        for (int v = 0; v < m->named[a].n; ++v) {
            json_t *kv = json_object();
            for (int k = 0; k < m->named[a].values[v].kv.n; ++k)
                json_object_set_new(kv, m->named[a].values[v].kv.kv[k].key, json_string(m->named[a].values[v].kv.kv[k].value));
            json_array_append_new(values, json_pack("{s:s, s:o}", "label", m->named[a].values[v].label, "settings", kv));
        }
        json_array_append_new(axes, json_pack("{s:s, s:s, s:o}", "name", m->named[a].name, "kind",
                                              m->named[a].kind == MATRIX_SET ? "set" : "solver_opts", "values", values));
    }
    return axes;
}

static int write_json(const char *path, json_t *j)
{
    char tmp[1200];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    int bad = !j || json_dump_file(j, tmp, JSON_INDENT(2) | JSON_PRESERVE_ORDER) != 0 || rename(tmp, path) != 0;
    json_decref(j);
    return bad ? mpm_error(MPM_EINPUT, "%s: cannot write", path) : MPM_OK;
}

/* DIR/matrix.json (what the report needs) and DIR/provenance.json (one entry per invocation). */
/* The options of this invocation as given, so it can be run again
 * (scripts/reproduce.sh). */
static json_t *options_json(const MatrixRunOptions *o)
{
    json_t *only = json_array();
    for (int i = 0; i < o->n_only; ++i) json_array_append_new(only, json_string(o->only[i]));
    return json_pack("{s:o, s:i, s:o, s:o, s:b}", "only", only, "jobs", o->jobs,
                     "threads", o->threads > 0 ? json_integer(o->threads) : json_null(), "asset_dir",
                     o->asset_dir ? json_string(o->asset_dir) : json_null(), "check", o->check);
}

static int write_metadata(Run *r, int ranks, const MatrixRunOptions *o)
{
    int jobs = o->jobs;
    char path[1200];
    snprintf(path, sizeof path, "%s/matrix.json", r->dir);
    json_t *meta = json_pack("{s:s, s:s, s:s, s:s, s:o, s:b, s:O}", "name", r->m.name, "description", r->m.description,
                             "file", r->m.file, "baseline", r->m.baseline, "named_axes", named_axes_json(&r->m),
                             "report_mg_levels", r->m.report_mg_levels, "matrix", r->m.root);
    int st = write_json(path, meta);
    if (st) return st;
    snprintf(path, sizeof path, "%s/provenance.json", r->dir);
    json_t *all = json_load_file(path, 0, NULL);
    if (!json_is_object(all) || !json_is_array(json_object_get(all, "invocations"))) {
        json_decref(all);
        all = json_pack("{s:[]}", "invocations");
    }
    json_t *p = provenance_json(0, 1);
    if (p) {
        json_object_set_new(p, "ranks", json_integer(ranks));
        json_object_set_new(p, "jobs_per_rank", json_integer(jobs));
        json_object_set_new(p, "cells_to_run", json_integer(r->n_todo));
        json_object_set_new(p, "options", options_json(o));
        json_array_append_new(json_object_get(all, "invocations"), p);
    }
    return write_json(path, all);
}

static void clear_tick(Run *r)
{
    if (r->tick_shown) fprintf(stderr, "\r\033[K");
    r->tick_shown = 0;
}

static void tick(void *ctx, int running)
{
    Run *r = ctx;
    double now = event_clock();
    if (!r->terminal || now - r->last_tick < 0.5) return;
    r->last_tick = now;
    double el = now - r->t_start;
    char eta[32] = "--";
    if (r->n_finished > 0) {
        double left = el / r->n_finished * (r->n_todo - r->n_finished);
        snprintf(eta, sizeof eta, "%dm%02ds", (int)(left / 60), (int)left % 60);
    }
    fprintf(stderr, "\r\033[Kmatrix %s: %d/%d cells done, %d running, elapsed %.0fs, ETA %s", r->m.name, r->n_finished,
            r->n_todo, running, el, eta);
    fflush(stderr);
    r->tick_shown = 1;
}

static int cell_done(void *ctx, const MatrixResult *res)
{
    Run *r = ctx;
    const MatrixCell *c = &r->cells.cells[res->index];
    static char row[16384];
    int st = matrix_results_row(&r->m, c, &res->outcome, &res->measure, row, sizeof row);
    if (!st) st = cells_file_append(&r->results, row);
    r->n_finished++;
    r->n_status[res->outcome.status]++;
    r->n_busy += res->outcome.busy;
    char name[1200], desc[1024];
    matrix_cell_name(c, name, sizeof name);
    matrix_cell_describe(&r->m, c, desc, sizeof desc);
    clear_tick(r);
    printf("[%d/%d] %s %s %s: %s, %d frames, %d steps, %ld outer, %ld linear, %.2f s%s%s", r->n_finished, r->n_todo,
           c->id, name, desc, cell_status_name(res->outcome.status), res->measure.frames, res->measure.steps,
           res->measure.outer_iters, res->measure.linear_iters, res->outcome.elapsed_s,
           res->outcome.busy ? " (machine busy)" : "", res->rank ? "" : "\n");
    if (res->rank) printf(" (rank %d)\n", res->rank);
    fflush(stdout);
    return st;
}

static void list_cells(const Run *r)
{
    printf("matrix %s (%s): %d cells, %d done, %d to run; results in %s\n", r->m.name, r->m.file, r->cells.n,
           r->n_done_before, r->n_todo, r->dir);
    for (int i = 0; i < r->cells.n; ++i) {
        const MatrixCell *c = &r->cells.cells[i];
        char name[1200], desc[1024];
        matrix_cell_name(c, name, sizeof name);
        matrix_cell_describe(&r->m, c, desc, sizeof desc);
        printf("%s  %-5s %s %s\n", c->id, cells_file_has(&r->results, c->id) ? "done" : "todo", name, desc);
    }
}

/* Longest expected first (from the times of cells.csv's rows); unknown ones
 * first, in matrix order, as they may be the longest. */
static void order_by_estimate(Run *r)
{
    double *est = malloc(sizeof *est * (size_t)(r->n_todo + 1));
    if (!est) return; /* matrix order then */
    for (int k = 0; k < r->n_todo; ++k) {
        const MatrixCell *c = &r->cells.cells[r->todo[k]];
        char scale[32];
        matrix_format_number(c->run.scale, scale, sizeof scale);
        est[k] = cells_file_estimate(&r->results, c->run.scene, c->run.solver, scale);
        if (est[k] < 0) est[k] = 1e300;
    }
    for (int i = 1; i < r->n_todo; ++i) { /* stable insertion sort, descending */
        double e = est[i];
        int t = r->todo[i], j = i;
        while (j > 0 && est[j - 1] < e) {
            est[j] = est[j - 1];
            r->todo[j] = r->todo[j - 1];
            --j;
        }
        est[j] = e;
        r->todo[j] = t;
    }
    free(est);
}

/* The cells.csv status of a cell done before this invocation ("" if none). */
static const char *done_status(const Run *r, const char *id)
{
    const CsvTable *t = &r->results.rows;
    int cid = csv_col(t, "id"), cst = csv_col(t, "status");
    const char *s = "";
    for (int i = 0; i < t->n_rows; ++i)
        if (!strcmp(csv_get(t, i, cid), id)) s = csv_get(t, i, cst);
    return s;
}

static void print_skip(const Run *r, const MatrixCell *c, const MatrixCell *ref, const char *why)
{
    char name[1200], desc[1024];
    matrix_cell_name(c, name, sizeof name);
    matrix_cell_describe(&r->m, c, desc, sizeof desc);
    printf("[skipped] %s %s %s: its reference run %s %s\n", c->id, name, desc, ref->id, why);
    fflush(stdout);
}

static void skipped(void *ctx, const MatrixTask *t, const MatrixTask *dep)
{
    Run *r = ctx;
    r->n_skipped++;
    clear_tick(r);
    print_skip(r, &r->cells.cells[t->index], &r->cells.cells[dep ? dep->index : t->index],
               dep ? "did not end ok (see cells.csv)" : "did not run");
}

static int build_tasks(Run *r, MatrixTask **out)
{
    MatrixTask *t = calloc((size_t)(r->n_todo + 1), sizeof *t);
    int *pos = malloc(sizeof(int) * (size_t)(r->cells.n + 1)); /* cell index -> task position */
    if (!t || !pos) {
        free(t);
        free(pos);
        return mpm_error(MPM_EINTERNAL, "out of memory (%d tasks)", r->n_todo);
    }
    for (int i = 0; i < r->cells.n; ++i) pos[i] = -1;
    for (int k = 0; k < r->n_todo; ++k) pos[r->todo[k]] = k;
    int n = 0;
    for (int k = 0; k < r->n_todo; ++k) {
        const MatrixCell *c = &r->cells.cells[r->todo[k]];
        t[n].after = c->ref >= 0 ? pos[c->ref] : -1;
        if (c->ref >= 0 && pos[c->ref] < 0) { /* the reference was done before: only an ok one serves */
            const char *s = done_status(r, r->cells.cells[c->ref].id);
            if (strcmp(s, "ok") != 0) {
                char why[64];
                snprintf(why, sizeof why, "ended %s in an earlier run (see cells.csv)", s);
                print_skip(r, c, &r->cells.cells[c->ref], why);
                r->n_skipped++;
                continue;
            }
        }
        t[n].index = r->todo[k];
        t[n].first_timed_frame = c->first_timed_frame;
        t[n].ranks = c->run.ranks;
        t[n].timeout_s = c->timeout_s;
        /* a reference that simulates a whole animation for its checkpoints can outlast the session:
         * it leaves resume checkpoints, and a later matrix run goes on from them (matrix_resume.h) */
        MatrixCell cell = *c;
        t[n].resumable = c->is_reference && c->sample_frames;
        if (t[n].resumable) cell.run.checkpoint_every_s = r->checkpoint_every_s;
        int w = snprintf(t[n].dir, sizeof t[n].dir, "%s/cells/%s", r->dir, c->id);
        int st = w < 0 || (size_t)w >= sizeof t[k].dir ? mpm_error(MPM_EINPUT, "%s: output path too long", r->dir) : MPM_OK;
        if (!st) st = matrix_cell_argv(&r->m, &cell, t[n].dir, t[n].args, sizeof t[n].args, &t[n].argc);
        if (st) {
            free(t);
            free(pos);
            return st;
        }
        size_t len = 0;
        for (int a = 0; a < t[n].argc; ++a) len += strlen(t[n].args + len) + 1;
        t[n].args_len = (int)len;
        n++;
    }
    /* positions shift past skipped tasks: remap the dependencies */
    for (int k = 0; k < r->cells.n; ++k) pos[k] = -1;
    for (int k = 0; k < n; ++k) pos[t[k].index] = k;
    for (int k = 0; k < n; ++k) {
        const MatrixCell *c = &r->cells.cells[t[k].index];
        t[k].after = c->ref >= 0 ? pos[c->ref] : -1;
    }
    free(pos);
    r->n_todo = n;
    *out = t;
    return MPM_OK;
}

/* A column new to cells.csv (a named axis, error_ref, repeat, role,
 * reference): the value of the cell with that id. */
static int fill_column(void *ctx, const char *id, const char *column, char *out, size_t cap)
{
    const Run *r = ctx;
    int a = matrix_named_index(&r->m, column), k = matrix_column_find(column);
    for (int i = 0; i < r->cells.n && (a >= 0 || k >= 0); ++i) {
        const MatrixCell *c = &r->cells.cells[i];
        if (strcmp(c->id, id)) continue;
        if (a >= 0) snprintf(out, cap, "%s", r->m.named[a].values[c->value[a]].label);
        else matrix_results_field(c, NULL, (MatrixColumn)k, out, cap);
        return 1;
    }
    return 0;
}

/* Everything rank 0 does before the cells run; *go = 0 for a dry run. */
static int prepare(Run *r, const char *file, const MatrixRunOptions *o, int use_mpi, int ranks, int *go)
{
    *go = 0;
    int st = matrix_load(file, &r->m);
    if (st) return st;
    if (o->asset_dir) {
        Matrix *m = &r->m;
        char cwd[1024] = ".";
        if (o->asset_dir[0] != '/' && !getcwd(cwd, sizeof cwd)) return mpm_error(MPM_EINTERNAL, "getcwd failed");
        char dir[2200];
        if (o->asset_dir[0] == '/') snprintf(dir, sizeof dir, "%s", o->asset_dir);
        else snprintf(dir, sizeof dir, "%s/%s", cwd, o->asset_dir);
        int k = run_setting_index("asset_dir");
        if (!(m->defaults.run.asset_dir = matrix_keep(m, dir))) return mpm_error(MPM_EINTERNAL, "out of memory");
        m->defaults.given |= 1ull << k;
        m->defaults.origin[k] = "--asset-dir";
    }
    if (o->threads > 0) {
        if (matrix_axis_length(&r->m, "threads"))
            return mpm_error(MPM_EINPUT, "--threads %d: %s has a threads axis (axes.threads)", o->threads, r->m.base);
        int k = run_setting_index("threads");
        r->m.defaults.run.threads = o->threads;
        r->m.defaults.given |= 1ull << k;
        r->m.defaults.origin[k] = "--threads";
    }
    if ((st = matrix_expand(&r->m, &r->cells))) return st;
    if ((st = select_cells(r, o))) return st;
    if (o->out_dir) snprintf(r->dir, sizeof r->dir, "%s", o->out_dir);
    else snprintf(r->dir, sizeof r->dir, "out/matrix-%s", r->m.name);
    char header[8192], cells_dir[1100];
    if ((st = matrix_results_header(&r->m, header, sizeof header))) return st;
    /* what is done, without writing anything: a bad matrix leaves no trace */
    if ((st = cells_file_open(r->dir, header, 0, NULL, NULL, &r->results))) return st;
    int *load = calloc((size_t)r->cells.n + 1, sizeof *load);
    r->todo = calloc((size_t)r->cells.n + 1, sizeof *r->todo);
    if (!load || !r->todo) {
        free(load);
        return mpm_error(MPM_EINTERNAL, "out of memory");
    }
    for (int i = 0; i < r->cells.n; ++i) {
        load[i] = !cells_file_has(&r->results, r->cells.cells[i].id);
        if (load[i]) r->todo[r->n_todo++] = i;
        else r->n_done_before++;
    }
    st = matrix_validate_cells(&r->m, &r->cells, load);
    free(load);
    if (st) return st;
    if (o->dry_run) {
        list_cells(r);
        return MPM_OK;
    }
    cells_file_close(&r->results);
    snprintf(cells_dir, sizeof cells_dir, "%s/cells", r->dir);
    if ((st = paths_mkdir_p(cells_dir))) return st;
    if ((st = cells_file_open(r->dir, header, 1, fill_column, r, &r->results))) return st;
    if (use_mpi && ranks > 1) order_by_estimate(r);
    if ((st = write_metadata(r, ranks, o))) return st;
    printf("matrix %s: %d cells, %d done already, %d to run on %d rank%s x %d job%s; results in %s/cells.csv\n",
           r->m.name, r->cells.n, r->n_done_before, r->n_todo, ranks, ranks > 1 ? "s" : "", o->jobs,
           o->jobs > 1 ? "s" : "", r->dir);
    fflush(stdout);
    *go = 1;
    return MPM_OK;
}

/* Waits for a non-blocking MPI operation with short sleeps: a rank waiting
 * for others (while rank 0 validates, or at the end while other ranks still
 * run cells) must not spin on a core a cell needs. */
static void mpi_wait_sleeping(MPI_Request *req)
{
    int done = 0;
    for (;;) {
        MPI_Test(req, &done, MPI_STATUS_IGNORE);
        if (done) return;
        matrix_sleep_ms(5);
    }
}

static void run_free(Run *r)
{
    cells_file_close(&r->results);
    matrix_cells_free(&r->cells);
    matrix_free(&r->m);
    free(r->todo);
}

int matrix_run(const char *file, const MatrixRunOptions *o, int *failed)
{
    *failed = 0;
    int use_mpi = under_mpi_launcher(), rank = 0, ranks = 1;
    if (use_mpi) {
        if (MPI_Init(NULL, NULL) != MPI_SUCCESS) return mpm_error(MPM_EINTERNAL, "MPI_Init failed");
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
        MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    }
    static Run r;
    memset(&r, 0, sizeof r);
    r.results.fd = -1;
    int go = 0, st = MPM_OK;
    MatrixTask *tasks = NULL;
    if (rank == 0) st = prepare(&r, file, o, use_mpi, ranks, &go);
    if (go && rank == 0) {
        /* before the other ranks hear go: an error here must stop them too */
        r.checkpoint_every_s = o->checkpoint_every_s > 0 ? o->checkpoint_every_s : MATRIX_RESUME_EVERY_S;
        if ((st = build_tasks(&r, &tasks))) go = 0;
        const char *ci = getenv("CI");
        r.terminal = isatty(STDERR_FILENO) && !(ci && *ci);
        r.t_start = event_clock();
    }
    if (use_mpi) {
        MPI_Request req;
        MPI_Ibcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD, &req);
        mpi_wait_sleeping(&req);
    }
    if (go) {
        /* every rank leaves the dispatch on every path (matrix_dispatch.c's
         * protocol); rank 0 returns the study's error, whichever rank had it */
        MatrixDispatchHooks hooks = {cell_done, tick, skipped, &r};
        st = matrix_dispatch(tasks, rank == 0 ? r.n_todo : 0, o->jobs, use_mpi, &hooks);
        if (rank == 0) {
            clear_tick(&r);
            printf("matrix %s: %d cells ran (%d ok, %d bad-input, %d failed, %d crashed, %d timeout, %d time-limit) in "
                   "%.3f s; %s/cells.csv\n",
                   r.m.name, r.n_finished, r.n_status[CELL_OK], r.n_status[CELL_BAD_INPUT], r.n_status[CELL_FAILED],
                   r.n_status[CELL_CRASHED], r.n_status[CELL_TIMEOUT], r.n_status[CELL_TIME_LIMIT],
                   event_clock() - r.t_start, r.dir);
            if (r.n_busy)
                printf("matrix %s: %d cells ran while other processes used the machine (machine_busy = 1 in "
                       "cells.csv): their times are not valid\n", r.m.name, r.n_busy);
            if (r.n_skipped)
                printf("matrix %s: %d cells skipped: their reference run did not end ok\n", r.m.name, r.n_skipped);
            if (!st && o->check && !(st = matrix_check_all(&r.m, &r.cells, r.dir, failed)) && *failed)
                fprintf(stderr, "mpmbench: matrix run --check: %d of %d cells failed (%s/check.csv)\n", *failed,
                        r.cells.n, r.dir);
        }
    }
    free(tasks);
    run_free(&r);
    if (use_mpi) {
        MPI_Request req;
        MPI_Ibarrier(MPI_COMM_WORLD, &req);
        mpi_wait_sleeping(&req);
        MPI_Finalize();
    }
    return st;
}
