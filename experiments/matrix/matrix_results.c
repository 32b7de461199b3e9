#ifndef _XOPEN_SOURCE
#define _XOPEN_SOURCE 700 /* nftw */
#endif
#include "experiments/matrix/matrix_results.h"

#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/error.h"
#include "experiments/io/paths.h"

static int remove_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
    (void)sb;
    (void)flag;
    (void)ftw;
    return remove(path) != 0 && errno != ENOENT;
}

int matrix_remove_tree(const char *path)
{
    struct stat st;
    if (lstat(path, &st) != 0) return MPM_OK;
    if (nftw(path, remove_entry, 16, FTW_DEPTH | FTW_PHYS) != 0)
        return mpm_error(MPM_EINTERNAL, "%s: cannot remove the unfinished cell directory", path);
    return MPM_OK;
}

static int put(char *out, size_t cap, size_t *len, const char *field, int first)
{
    if (!first) {
        if (*len + 2 >= cap) return -1;
        out[(*len)++] = ',';
        out[*len] = '\0';
    }
    return csv_put(out, cap, len, field);
}

int matrix_results_has(const Matrix *m, MatrixColumn k)
{
    switch (matrix_columns[k].when) {
    case MATRIX_COL_WITH_ERROR_REF:
        return m->uses_error_ref;
    case MATRIX_COL_WITH_REPEAT:
        return m->repeat > 1;
    case MATRIX_COL_WITH_REFERENCES:
        return m->has_references;
    case MATRIX_COL_WITH_SAMPLES:
        return m->has_samples;
    case MATRIX_COL_WITH_RANKS:
        return m->uses_ranks;
    case MATRIX_COL_ALWAYS:
        break;
    }
    return 1;
}

int matrix_results_header(const Matrix *m, char *out, size_t cap)
{
    size_t len = 0;
    out[0] = '\0';
    int bad = 0, first = 1;
    for (int k = 0; k < MATRIX_COLS; ++k) {
        if (!matrix_results_has(m, (MatrixColumn)k)) continue;
        if (k != MATRIX_COL_NAMED_AXES) bad |= put(out, cap, &len, matrix_columns[k].name, first);
        for (int a = 0; k == MATRIX_COL_NAMED_AXES && a < m->n_named; ++a) bad |= put(out, cap, &len, m->named[a].name, 0);
        first = 0;
    }
    bad |= len + strlen(cell_measure_columns) + 2 >= cap;
    if (!bad) snprintf(out + len, cap - len, ",%s", cell_measure_columns);
    return bad ? mpm_error(MPM_EINPUT, "%s: too many columns", m->base) : MPM_OK;
}

static void kv_join(const MatrixKv *kv, int n, char *out, size_t cap)
{
    size_t len = 0;
    out[0] = '\0';
    for (int i = 0; i < n && len < cap; ++i)
        len += (size_t)snprintf(out + len, cap - len, "%s%s=%s", i ? ";" : "", kv[i].key, kv[i].value);
}

void matrix_results_field(const MatrixCell *c, const CellMeasure *x, MatrixColumn k, char *out, size_t cap)
{
    /* the counts the run used when the matrix left them to OpenMP / the scene (run.json) */
    int threads = c->run.threads > 0 || !x || x->threads_run <= 0 ? c->run.threads : x->threads_run;
    int frames = c->run.frames > 0 || !x || x->frames_run <= 0 ? c->run.frames : x->frames_run;
    out[0] = '\0';
    switch (k) {
    case MATRIX_COL_ID:
        snprintf(out, cap, "%s", c->id);
        break;
    case MATRIX_COL_SCENE:
        snprintf(out, cap, "%s", c->run.scene);
        break;
    case MATRIX_COL_SOLVER:
        snprintf(out, cap, "%s", c->run.solver);
        break;
    case MATRIX_COL_EPS:
        matrix_format_number(c->run.eps, out, cap);
        break;
    case MATRIX_COL_SCALE:
        matrix_format_number(c->run.scale, out, cap);
        break;
    case MATRIX_COL_THREADS:
        snprintf(out, cap, "%d", threads);
        break;
    case MATRIX_COL_RANKS:
        snprintf(out, cap, "%d", c->run.ranks > 0 ? c->run.ranks : 1);
        break;
    case MATRIX_COL_FRAMES_ASKED:
        snprintf(out, cap, "%d", frames);
        break;
    case MATRIX_COL_FIRST_TIMED_FRAME:
        snprintf(out, cap, "%d", c->first_timed_frame);
        break;
    case MATRIX_COL_ERROR_REF:
        snprintf(out, cap, "%s", c->run.error_ref ? c->run.error_ref : "");
        break;
    case MATRIX_COL_REPEAT:
        snprintf(out, cap, "%d", c->repeat);
        break;
    case MATRIX_COL_ROLE:
        snprintf(out, cap, "%s", c->is_reference ? "reference" : "cell");
        break;
    case MATRIX_COL_REFERENCE:
        snprintf(out, cap, "%s", c->ref_id);
        break;
    case MATRIX_COL_SAMPLE_FRAMES:
        snprintf(out, cap, "%s", c->sample_frames && !c->is_reference ? c->sample_frames : "");
        break;
    case MATRIX_COL_SET:
        kv_join(c->set, c->n_set, out, cap);
        break;
    case MATRIX_COL_SOLVER_OPTS:
        kv_join(c->solver_opts, c->n_solver_opts, out, cap);
        break;
    case MATRIX_COL_NAMED_AXES:
    case MATRIX_COLS:
        break;
    }
}

int matrix_results_row(const Matrix *m, const MatrixCell *c, const CellOutcome *o, const CellMeasure *x, char *out,
                       size_t cap)
{
    size_t len = 0;
    char text[4096];
    int bad = 0, first = 1;
    out[0] = '\0';
    for (int k = 0; k < MATRIX_COLS; ++k) {
        if (!matrix_results_has(m, (MatrixColumn)k)) continue;
        if (k != MATRIX_COL_NAMED_AXES) {
            matrix_results_field(c, x, (MatrixColumn)k, text, sizeof text);
            bad |= put(out, cap, &len, text, first);
        }
        for (int a = 0; k == MATRIX_COL_NAMED_AXES && a < m->n_named; ++a)
            bad |= put(out, cap, &len, m->named[a].values[c->value[a]].label, 0);
        first = 0;
    }
    /* the measurement fields need no quoting: numbers and status names */
    bad |= cell_measure_format(o, x, text, sizeof text) || len + strlen(text) + 2 >= cap;
    if (!bad) snprintf(out + len, cap - len, ",%s", text);
    return bad ? mpm_error(MPM_EINTERNAL, "cells.csv row of cell %s too long", c->id) : MPM_OK;
}

static int write_all(int fd, const char *buf, size_t n)
{
    while (n > 0) {
        ssize_t w = write(fd, buf, n);
        if (w < 0) {
            if (errno == EINTR) continue;
            return -1;
        }
        buf += w;
        n -= (size_t)w;
    }
    return 0;
}

static void sync_dir(const char *dir)
{
    int fd = open(dir, O_RDONLY);
    if (fd >= 0) {
        fsync(fd);
        close(fd);
    }
}

/* Replaces path by content atomically (temporary file, fsync, rename). */
static int replace_file(const char *dir, const char *path, const char *content, size_t n)
{
    char tmp[1200];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return mpm_error(MPM_EINPUT, "%s: cannot write", tmp);
    int bad = write_all(fd, content, n) || fsync(fd);
    bad |= close(fd);
    if (bad || rename(tmp, path) != 0) return mpm_error(MPM_EINPUT, "%s: cannot write", path);
    sync_dir(dir);
    return MPM_OK;
}

static char *read_file(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 65536, len = 0;
    char *buf = malloc(cap);
    while (buf) {
        size_t r = fread(buf + len, 1, cap - len - 1, f);
        len += r;
        if (r == 0) break;
        if (cap - len < 4096) {
            char *b = realloc(buf, cap * 2);
            if (!b) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = b;
            cap *= 2;
        }
    }
    fclose(f);
    if (buf) buf[len] = '\0';
    *n = len;
    return buf;
}

static int cmp_str(const void *a, const void *b) { return strcmp(*(const char *const *)a, *(const char *const *)b); }

/* The old rows under the new header, by column name. */
static int remap(const char *dir, const char *path, const CsvTable *old, const char *header, CellsFillFn fill,
                 void *fill_ctx)
{
    CsvTable h;
    int st = csv_parse(header, strlen(header), &h);
    if (st) return st;
    size_t cap = strlen(header) + 2, len = 0;
    for (int r = 0; r < old->n_rows; ++r) {
        cap += (size_t)h.n_cols * (2 * 256 + 1) + 4; /* filled values: at most 255 characters, quoted */
        for (int c = 0; c < old->n_cols; ++c) cap += 2 * strlen(old->rows[r][c]) + 4;
    }
    char *buf = malloc(cap);
    if (!buf) {
        csv_free(&h);
        return mpm_error(MPM_EINTERNAL, "out of memory");
    }
    len = (size_t)snprintf(buf, cap, "%s\n", header);
    int c_id = csv_col(old, "id");
    for (int r = 0; r < old->n_rows; ++r) {
        for (int c = 0; c < h.n_cols; ++c) {
            if (c) buf[len++] = ',';
            buf[len] = '\0';
            int oc = csv_col(old, h.header[c]);
            char filled[256] = "";
            if (oc < 0 && fill) fill(fill_ctx, csv_get(old, r, c_id), h.header[c], filled, sizeof filled);
            csv_put(buf, cap, &len, oc >= 0 ? csv_get(old, r, oc) : filled);
        }
        buf[len++] = '\n';
    }
    st = replace_file(dir, path, buf, len);
    free(buf);
    csv_free(&h);
    return st;
}

static int index_ids(CellsFile *f)
{
    if (!f->rows.n_cols) return MPM_OK;
    int c = csv_col(&f->rows, "id");
    f->ids = malloc(sizeof *f->ids * (size_t)(f->rows.n_rows + 1));
    if (!f->ids) return mpm_error(MPM_EINTERNAL, "out of memory");
    for (int r = 0; r < f->rows.n_rows; ++r) f->ids[f->n_ids++] = csv_get(&f->rows, r, c);
    qsort(f->ids, (size_t)f->n_ids, sizeof *f->ids, cmp_str);
    return MPM_OK;
}

int cells_file_open(const char *dir, const char *header, int writable, CellsFillFn fill, void *fill_ctx,
                    CellsFile *f)
{
    memset(f, 0, sizeof *f);
    f->fd = -1;
    snprintf(f->path, sizeof f->path, "%s/cells.csv", dir);
    size_t n = 0;
    char *data = read_file(f->path, &n);
    size_t keep = 0; /* bytes of whole lines */
    for (size_t i = n; i > 0; --i)
        if (data[i - 1] == '\n') {
            keep = i;
            break;
        }
    if (!writable) { /* what a writable open would keep, without changing the file */
        int st = keep ? csv_parse(data, keep, &f->rows) : MPM_OK;
        free(data);
        if (st) return st;
        return index_ids(f);
    }
    int st = MPM_OK;
    size_t header_len = strlen(header);
    if (keep == 0) { /* new, or not even a whole header line */
        char *h = malloc(header_len + 2);
        if (!h) st = mpm_error(MPM_EINTERNAL, "out of memory");
        else {
            memcpy(h, header, header_len);
            h[header_len] = '\n';
            st = replace_file(dir, f->path, h, header_len + 1);
            free(h);
        }
        keep = 0;
    } else {
        if (keep < n && truncate(f->path, (off_t)keep) != 0)
            st = mpm_error(MPM_EINPUT, "%s: cannot drop the row cut short", f->path);
        if (!st) st = csv_parse(data, keep, &f->rows);
        const char *nl = memchr(data, '\n', keep);
        size_t first_len = (size_t)(nl - data);
        if (first_len && data[first_len - 1] == '\r') first_len--;
        if (!st && (first_len != header_len || memcmp(data, header, header_len) != 0))
            st = remap(dir, f->path, &f->rows, header, fill, fill_ctx);
    }
    free(data);
    if (!st) st = index_ids(f);
    if (!st && (f->fd = open(f->path, O_WRONLY | O_APPEND | O_CLOEXEC)) < 0)
        st = mpm_error(MPM_EINPUT, "%s: cannot open for appending", f->path);
    if (st) cells_file_close(f);
    return st;
}

int cells_file_has(const CellsFile *f, const char *id)
{
    return f->n_ids && bsearch(&id, f->ids, (size_t)f->n_ids, sizeof *f->ids, cmp_str) != NULL;
}

double cells_file_estimate(const CellsFile *f, const char *scene, const char *solver, const char *scale)
{
    const CsvTable *t = &f->rows;
    int c_scene = csv_col(t, "scene"), c_solver = csv_col(t, "solver"), c_scale = csv_col(t, "scale"),
        c_el = csv_col(t, "elapsed_s");
    if (c_el < 0) return -1.0;
    for (int level = 0; level < 3; ++level) {
        double sum = 0.0;
        int n = 0;
        for (int r = 0; r < t->n_rows; ++r) {
            if (strcmp(csv_get(t, r, c_solver), solver)) continue;
            if (level < 2 && strcmp(csv_get(t, r, c_scene), scene)) continue;
            if (level < 1 && strcmp(csv_get(t, r, c_scale), scale)) continue;
            sum += strtod(csv_get(t, r, c_el), NULL);
            n++;
        }
        if (n) return sum / n;
    }
    return -1.0;
}

int cells_file_append(CellsFile *f, const char *row)
{
    size_t n = strlen(row);
    char *line = malloc(n + 2);
    if (!line) return mpm_error(MPM_EINTERNAL, "out of memory");
    memcpy(line, row, n);
    line[n] = '\n';
    /* one write: a kill leaves the row whole or absent (or, rarely, cut, which the next open drops) */
    ssize_t w;
    do {
        w = write(f->fd, line, n + 1);
    } while (w < 0 && errno == EINTR);
    free(line);
    if (w != (ssize_t)(n + 1) || fsync(f->fd) != 0) return mpm_error(MPM_EINTERNAL, "%s: cannot append a row", f->path);
    return MPM_OK;
}

void cells_file_close(CellsFile *f)
{
    if (f->fd >= 0) close(f->fd);
    f->fd = -1;
    free(f->ids);
    f->ids = NULL;
    f->n_ids = 0;
    csv_free(&f->rows);
}
