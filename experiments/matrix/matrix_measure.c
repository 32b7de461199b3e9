#include "experiments/matrix/matrix_measure.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "core/error.h"
#include "experiments/io/csv_table.h"

const char *cell_status_name(CellStatus s)
{
    switch (s) {
    case CELL_OK: return "ok";
    case CELL_BAD_INPUT: return "bad-input";
    case CELL_FAILED: return "failed";
    case CELL_CRASHED: return "crashed";
    case CELL_TIMEOUT: return "timeout";
    case CELL_TIME_LIMIT: return "time-limit";
    case CELL_N_STATUS: break;
    }
    return "failed";
}

CellOutcome cell_outcome(int wait_status, int timed_out, double elapsed_s, long peak_rss_kb)
{
    CellOutcome o = {CELL_FAILED, 0, elapsed_s, peak_rss_kb, 0.0, -1.0, -1.0, 0};
    if (WIFEXITED(wait_status)) {
        o.exit_code = WEXITSTATUS(wait_status);
        o.status = o.exit_code == 0 ? CELL_OK : o.exit_code == 2 ? CELL_BAD_INPUT : CELL_FAILED;
    } else if (WIFSIGNALED(wait_status)) {
        o.exit_code = -WTERMSIG(wait_status);
        o.status = CELL_CRASHED;
    }
    if (timed_out) o.status = CELL_TIMEOUT;
    return o;
}

/* Severity of a solve status name (solvers/solver.h order; unknown names last). */
static int severity(const char *s)
{
    static const char *const order[] = {"converged", "capped", "stalled", "timeout", "failed"};
    for (int i = 0; i < 5; ++i)
        if (!strcmp(s, order[i])) return i;
    return 5;
}

static double num(const char *s) { return s[0] ? strtod(s, NULL) : 0.0; }


/* A frame that did not reach its end: frames.csv complete = 0, or (files
 * written before that column) status timeout for --max-run-seconds. */
static int frame_incomplete(const CsvTable *t, int r, int c_complete, int c_status, int c_reason)
{
    if (c_complete >= 0) return !strcmp(csv_get(t, r, c_complete), "0");
    return c_reason >= 0 && !strcmp(csv_get(t, r, c_status), "timeout") &&
           strstr(csv_get(t, r, c_reason), "--max-run-seconds") != NULL;
}

void cell_measure(const char *dir, int first_timed_frame, CellMeasure *m)
{
    memset(m, 0, sizeof *m);
    m->inner_iters = -1;
    m->startup_s = -1.0;
    char path[1200];
    CsvTable t;
    snprintf(path, sizeof path, "%s/frames.csv", dir);
    int last_timeout = 0;
    if (csv_read(path, &t) == MPM_OK) {
        int c_frame = csv_col(&t, "frame"), c_outer = csv_col(&t, "outer_iters"), c_lin = csv_col(&t, "linear_iters"),
            c_inner = csv_col(&t, "inner_iters"), c_wall = csv_col(&t, "wall_s"), c_res = csv_col(&t, "max_residual"),
            c_status = csv_col(&t, "status"), c_complete = csv_col(&t, "complete"), c_reason = csv_col(&t, "reason");
        if (c_inner >= 0) m->inner_iters = 0;
        int worst = -1;
        for (int r = 0; r < t.n_rows; ++r) {
            double wall = num(csv_get(&t, r, c_wall)), res = num(csv_get(&t, r, c_res));
            const char *s = csv_get(&t, r, c_status);
            if (severity(s) > worst) {
                worst = severity(s);
                snprintf(m->worst_solve_status, sizeof m->worst_solve_status, "%s", s);
            }
            if (res > m->max_residual) m->max_residual = res;
            m->wall_s += wall;
            if (frame_incomplete(&t, r, c_complete, c_status, c_reason)) {
                /* its time is in wall_s only: not a frame. Only the time
                 * limit cuts a run short; a frame a failed step ended is the
                 * run's result (worst_solve_status failed), not a limit */
                if (!strcmp(s, "timeout")) m->cut_short = 1;
                continue;
            }
            m->frames++;
            m->outer_iters += atol(csv_get(&t, r, c_outer));
            m->linear_iters += atol(csv_get(&t, r, c_lin));
            if (c_inner >= 0) m->inner_iters += atol(csv_get(&t, r, c_inner));
            if (atoi(csv_get(&t, r, c_frame)) >= first_timed_frame) {
                m->timed_frames++;
                m->timed_wall_s += wall;
                if (wall > m->max_frame_s) m->max_frame_s = wall;
            }
        }
        last_timeout = t.n_rows > 0 && !strcmp(csv_get(&t, t.n_rows - 1, c_status), "timeout");
        csv_free(&t);
    }
    mpm_clear_error(); /* a missing file is a result here, not an error */
    snprintf(path, sizeof path, "%s/steps.csv", dir);
    if (csv_read(path, &t) == MPM_OK) {
        int c_status = csv_col(&t, "status"), c_part = csv_col(&t, "particles"), c_res = csv_col(&t, "residual");
        int converged = 0;
        for (int r = 0; r < t.n_rows; ++r) {
            m->steps++;
            converged += !strcmp(csv_get(&t, r, c_status), "converged");
            long p = atol(csv_get(&t, r, c_part));
            if (p > m->particles) m->particles = p;
            double res = num(csv_get(&t, r, c_res));
            if (res > m->max_residual) m->max_residual = res;
        }
        m->converged_fraction = m->steps ? (double)converged / m->steps : 0.0;
        csv_free(&t);
    }
    mpm_clear_error();
    snprintf(path, sizeof path, "%s/run.json", dir);
    json_t *run = json_load_file(path, 0, NULL);
    json_t *s = run ? json_object_get(run, "startup_s") : NULL;
    if (json_is_number(s)) m->startup_s = json_number_value(s);
    json_t *f = run ? json_object_get(run, "frames") : NULL, *th = run ? json_object_get(run, "threads") : NULL;
    if (json_is_integer(f)) m->frames_run = (int)json_integer_value(f);
    if (json_is_integer(th)) m->threads_run = (int)json_integer_value(th);
    json_decref(run);
    /* stopped at the limit exactly at a frame's end: fewer frames, the last timed out */
    if (last_timeout && m->frames_run > 0 && m->frames < m->frames_run) m->cut_short = 1;
}

const char *const cell_measure_columns =
    "status,exit,frames,steps,outer_iters,linear_iters,inner_iters,wall_s,timed_frames,timed_wall_s,s_per_frame,"
    "max_frame_s,max_residual,converged_fraction,worst_solve_status,particles,peak_rss_mb,startup_s,elapsed_s,"
    "cpu_s,others_cpu_s,load_start,machine_busy";

int cell_measure_format(const CellOutcome *o, const CellMeasure *m, char *out, size_t cap)
{
    char inner[32] = "", startup[32] = "", others[32] = "", load[32] = "";
    if (m->inner_iters >= 0) snprintf(inner, sizeof inner, "%ld", m->inner_iters);
    if (m->startup_s >= 0) snprintf(startup, sizeof startup, "%.6f", m->startup_s);
    if (o->others_cpu_s >= 0) snprintf(others, sizeof others, "%.3f", o->others_cpu_s);
    if (o->load_start >= 0) snprintf(load, sizeof load, "%.2f", o->load_start);
    int w = snprintf(out, cap, "%s,%d,%d,%d,%ld,%ld,%s,%.6f,%d,%.6f,%.6f,%.6f,%.6e,%.6f,%s,%ld,%.1f,%s,%.3f,%.3f,%s,%s,%d",
                     cell_status_name(o->status), o->exit_code, m->frames, m->steps, m->outer_iters, m->linear_iters,
                     inner, m->wall_s, m->timed_frames, m->timed_wall_s,
                     m->timed_frames ? m->timed_wall_s / m->timed_frames : 0.0, m->max_frame_s, m->max_residual,
                     m->converged_fraction, m->worst_solve_status, m->particles, o->peak_rss_kb / 1024.0, startup,
                     o->elapsed_s, o->cpu_s, others, load, o->busy);
    return w < 0 || (size_t)w >= cap ? -1 : 0;
}
