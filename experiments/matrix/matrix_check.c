/* The stability verdict of matrix cells (matrix_check.h). */
#include "experiments/matrix/matrix_check.h"

#include <jansson.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "experiments/matrix/matrix_results.h"

static void add(char *buf, size_t cap, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void add(char *buf, size_t cap, const char *fmt, ...)
{
    size_t len = strlen(buf);
    if (len + 8 >= cap) return;
    if (len) len += (size_t)snprintf(buf + len, cap - len, "; ");
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf + len, cap - len, fmt, ap);
    va_end(ap);
}

static void fail(CellCheck *out, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void fail(CellCheck *out, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    out->pass = 0;
    add(out->reasons, sizeof out->reasons, "%s", msg);
}

/* The first line of a file (a cell's stderr.txt), "" when none. */
static void first_line(const char *path, const char *containing, char *out, size_t n)
{
    out[0] = '\0';
    FILE *f = fopen(path, "r");
    if (!f) return;
    char line[1024];
    while (fgets(line, sizeof line, f)) {
        line[strcspn(line, "\r\n")] = '\0';
        if (!containing || strstr(line, containing)) {
            snprintf(out, n, "%.500s", line);
            break;
        }
    }
    fclose(f);
}

/* A field that reads as a number that is not finite ("nan", "-inf", ...). */
static int non_finite(const char *s)
{
    if (!s[0]) return 0;
    char *end = NULL;
    double v = strtod(s, &end);
    return end && !*end && !isfinite(v);
}

static int text_column(const char *name)
{
    static const char *const text[] = {"scene", "solver", "status", "reason", "ref_solver", "ref_status", NULL};
    for (int i = 0; text[i]; ++i)
        if (!strcmp(name, text[i])) return 1;
    return 0;
}

/* NaN or Inf in a numeric column of DIR/NAME: the first one found. */
static void scan_non_finite(const CsvTable *t, const char *name, CellCheck *out)
{
    for (int r = 0; r < t->n_rows; ++r)
        for (int c = 0; c < t->n_cols; ++c)
            if (!text_column(t->header[c]) && non_finite(t->rows[r][c])) {
                fail(out, "%s row %d: %s = %s", name, r + 1, t->header[c], t->rows[r][c]);
                return;
            }
}

/* The stopping rule and the frame count the run recorded (run.json). */
static void run_info(const char *dir, char *stop, size_t n, int *frames)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/run.json", dir);
    snprintf(stop, n, "cn");
    *frames = -1;
    json_t *run = json_load_file(path, 0, NULL);
    if (!run) return;
    json_t *opts = json_object_get(run, "solver_options"), *f = json_object_get(run, "frames");
    json_t *s = opts ? json_object_get(opts, "stop") : NULL;
    if (json_is_string(s)) snprintf(stop, n, "%s", json_string_value(s));
    if (json_is_integer(f)) *frames = (int)json_integer_value(f);
    json_decref(run);
}

static int known_status(const char *s)
{
    static const char *const st[] = {"converged", "capped", "stalled", "timeout", "failed", NULL};
    for (int i = 0; st[i]; ++i)
        if (!strcmp(s, st[i])) return 1;
    return 0;
}

static void check_steps(const MatrixCell *c, const char *dir, CellCheck *out, const char **last_status)
{
    static char last[16];
    last[0] = '\0';
    *last_status = last;
    char path[1200], stop[32];
    int frames;
    run_info(dir, stop, sizeof stop, &frames);
    snprintf(path, sizeof path, "%s/steps.csv", dir);
    CsvTable t;
    if (csv_read(path, &t) != MPM_OK) {
        mpm_clear_error();
        fail(out, "no steps.csv");
        return;
    }
    int cs = csv_col(&t, "status"), cr = csv_col(&t, "residual"), ce = csv_col(&t, "max_energy_rise"),
        cf = csv_col(&t, "frame"), cp = csv_col(&t, "step");
    if (!t.n_rows) fail(out, "steps.csv has no step");
    if (ce < 0 && t.n_rows) fail(out, "steps.csv has no max_energy_rise column (an older binary?)");
    int bad_conv = 0, bad_status = 0, rise = 0;
    for (int r = 0; r < t.n_rows; ++r) {
        const char *s = csv_get(&t, r, cs), *fr = csv_get(&t, r, cf), *sp = csv_get(&t, r, cp);
        snprintf(last, sizeof last, "%s", s);
        if (!known_status(s) && !bad_status++) fail(out, "frame %s step %s: unknown status \"%s\"", fr, sp, s);
        double res = strtod(csv_get(&t, r, cr), NULL);
        /* the residual is printed with 7 digits: converged means below eps up to that rounding */
        if (!strcmp(s, "converged") && !strcmp(stop, "cn") && !(res < c->run.eps * (1.0 + 1e-6)) && !bad_conv++)
            fail(out, "frame %s step %s: status converged but residual %s is not below eps %g", fr, sp,
                 csv_get(&t, r, cr), c->run.eps);
        double up = ce >= 0 ? strtod(csv_get(&t, r, ce), NULL) : 0.0;
        if (up > 0.0 && !rise++)
            fail(out, "frame %s step %s: a line search accepted an energy increase of %s", fr, sp, csv_get(&t, r, ce));
    }
    if (bad_conv > 1) add(out->reasons, sizeof out->reasons, "(%d such steps)", bad_conv);
    scan_non_finite(&t, "steps.csv", out);
    csv_free(&t);
    snprintf(path, sizeof path, "%s/frames.csv", dir);
    if (csv_read(path, &t) != MPM_OK) {
        mpm_clear_error();
        fail(out, "no frames.csv");
        return;
    }
    scan_non_finite(&t, "frames.csv", out);
    int done = 0, fc = csv_col(&t, "complete");
    for (int r = 0; r < t.n_rows; ++r) done += fc < 0 || !strcmp(csv_get(&t, r, fc), "1");
    /* a run whose time budget ran out at a frame's end says so in the row of
     * the next frame (no steps, status timeout), not in its last step's */
    char last_frame[32] = "";
    if (t.n_rows) snprintf(last_frame, sizeof last_frame, "%s", csv_get(&t, t.n_rows - 1, csv_col(&t, "status")));
    csv_free(&t);
    int asked = c->run.frames > 0 ? c->run.frames : frames;
    int said = !strcmp(last, "failed") || !strcmp(last, "timeout") || !strcmp(last_frame, "failed") ||
               !strcmp(last_frame, "timeout");
    if (asked > 0 && done < asked && !said)
        fail(out, "ran %d of %d frames and its last step (%s) says nothing of why", done, asked, last[0] ? last : "none");
}

void matrix_check_cell(const MatrixCell *c, const char *dir, const CsvTable *t, int r, CellCheck *out)
{
    memset(out, 0, sizeof *out);
    out->pass = 1;
    const char *status = csv_get(t, r, csv_col(t, "status")), *exit_code = csv_get(t, r, csv_col(t, "exit"));
    char path[1200], line[600];
    snprintf(path, sizeof path, "%s/stderr.txt", dir);
    if (!strcmp(status, "timeout")) {
        fail(out, "killed at the wall-clock limit (cell_timeout_s %g, ran %s s)", c->timeout_s,
             csv_get(t, r, csv_col(t, "elapsed_s")));
    } else if (!strcmp(status, "crashed")) {
        fail(out, "crashed (signal %d)", -atoi(exit_code));
    } else if (!strcmp(status, "bad-input")) {
        first_line(path, NULL, line, sizeof line);
        fail(out, "bad input: %s", line[0] ? line : "(no message)");
    } else if (!strcmp(status, "failed")) {
        first_line(path, "left the domain", line, sizeof line);
        if (line[0]) {
            snprintf(out->notes, sizeof out->notes, "reported: %.200s", line);
        } else {
            first_line(path, NULL, line, sizeof line);
            fail(out, "exit %s: %s", exit_code, line[0] ? line : "(no message)");
        }
    } else if (!strcmp(status, "time-limit")) { /* the run's own limit, which it reported */
        snprintf(out->notes, sizeof out->notes, "reported: stopped at its max_run_seconds %g", c->run.max_run_s);
    } else if (strcmp(status, "ok") != 0) {
        fail(out, "status \"%s\"", status);
    }
    if (strcmp(status, "bad-input") != 0) {
        const char *last = "";
        check_steps(c, dir, out, &last);
    }
}

int matrix_check_all(const Matrix *m, const MatrixCells *cells, const char *dir, int *failed)
{
    *failed = 0;
    char path[1200];
    snprintf(path, sizeof path, "%s/cells.csv", dir);
    CsvTable t;
    int st = csv_read(path, &t);
    if (st) return st;
    snprintf(path, sizeof path, "%s/check.csv", dir);
    FILE *f = fopen(path, "w");
    if (!f) {
        csv_free(&t);
        return mpm_error(MPM_EINPUT, "%s: cannot write", path);
    }
    for (int k = 0; k <= MATRIX_CHECK_LAST_SHARED; ++k) fprintf(f, "%s%s", k ? "," : "", matrix_columns[k].name);
    for (int a = 0; a < m->n_named; ++a) fprintf(f, ",%s", m->named[a].name);
    for (int k = 0; matrix_check_columns[k]; ++k) fprintf(f, ",%s", matrix_check_columns[k]);
    fprintf(f, "\n");
    int cid = csv_col(&t, "id"), passed = 0;
    for (int i = 0; i < cells->n; ++i) {
        const MatrixCell *c = &cells->cells[i];
        int row = -1;
        for (int r = 0; r < t.n_rows; ++r)
            if (!strcmp(csv_get(&t, r, cid), c->id)) row = r; /* the last row of an id */
        CellCheck ck;
        char cdir[1200];
        snprintf(cdir, sizeof cdir, "%s/cells/%s", dir, c->id);
        if (row < 0) {
            memset(&ck, 0, sizeof ck);
            snprintf(ck.reasons, sizeof ck.reasons, "not run%s", c->ref >= 0 ? " (its reference run did not end ok?)" : "");
        } else {
            matrix_check_cell(c, cdir, &t, row, &ck);
        }
        char field[1100], line[4096];
        size_t len = 0;
        line[0] = '\0';
        for (int k = 0; k <= MATRIX_CHECK_LAST_SHARED; ++k) { /* cells.csv's first columns */
            if (k) {
                line[len++] = ',';
                line[len] = '\0';
            }
            matrix_results_field(c, NULL, (MatrixColumn)k, field, sizeof field);
            csv_put(line, sizeof line, &len, field);
        }
        for (int a = 0; a < m->n_named; ++a) {
            line[len++] = ',';
            line[len] = '\0';
            csv_put(line, sizeof line, &len, m->named[a].values[c->value[a]].label);
        }
        len += (size_t)snprintf(line + len, sizeof line - len, ",%d,", ck.pass);
        char why[1400];
        snprintf(why, sizeof why, "%s%s%s", ck.reasons, ck.reasons[0] && ck.notes[0] ? "; " : "", ck.notes);
        csv_put(line, sizeof line, &len, why);
        fprintf(f, "%s\n", line);
        if (ck.pass) {
            passed++;
            continue;
        }
        (*failed)++;
        char name[1200], desc[1024];
        matrix_cell_name(c, name, sizeof name);
        matrix_cell_describe(m, c, desc, sizeof desc);
        printf("check: FAIL %s %s %s: %s\n", c->id, name, desc, ck.reasons);
    }
    fclose(f);
    csv_free(&t);
    printf("check: %d of %d cells passed; %s/check.csv\n", passed, cells->n, dir);
    fflush(stdout);
    return MPM_OK;
}
