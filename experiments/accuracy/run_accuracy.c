/* The accuracy attachments of a run (run_accuracy.h). */
#include "experiments/accuracy/run_accuracy.h"

#include <jansson.h>
#include <math.h>
#include <string.h>
#include <sys/stat.h>

#include "core/error.h"
#include "experiments/io/csv_write.h"

const char *const run_accuracy_step_header = "err_h,e_gap,err_v_max,ref_solver,ref_status,ref_s";
const char *const run_accuracy_frame_header = "pos_rms,pos_max,vel_rms";

static int check_run_dir(const char *flag, const char *dir)
{
    if (!dir) return MPM_OK;
    char path[1200];
    struct stat sb;
    snprintf(path, sizeof path, "%s/run.json", dir);
    if (!dir[0] || stat(path, &sb) != 0)
        return mpm_error(MPM_EINPUT, "%s '%s': not a run directory (no %s)", flag, dir, path);
    return MPM_OK;
}

int run_accuracy_check(const AccuracyConfig *c)
{
    int st = MPM_OK;
    if (c->error_ref && (st = error_ref_check(c->error_ref))) return st;
    if ((st = check_run_dir("--dt-from", c->dt_from))) return st;
    return check_run_dir("--trajectory-ref", c->trajectory_ref);
}

int run_accuracy_create(const AccuracyConfig *c, RunAccuracy *a)
{
    memset(a, 0, sizeof *a);
    if (!c->error_ref) return MPM_OK;
    int st = error_ref_create(c->error_ref, &a->ref);
    if (!st) st = error_ref_startup(a->ref);
    return st;
}

int run_accuracy_bind(const AccuracyConfig *c, const Scene *sc, int frames, RunAccuracy *a)
{
    int st = MPM_OK;
    if (c->dt_from) {
        if ((st = dt_replay_load(&a->replay, c->dt_from, sc->name, sc->particles.n, frames))) return st;
        a->replaying = 1;
    }
    if (c->trajectory_ref) {
        if ((st = reference_run_check("--trajectory-ref", c->trajectory_ref, sc->name, sc->particles.n))) return st;
        if ((st = trajectory_reader_open(&a->reader, c->trajectory_ref, sc->name, sc->particles.n, frames))) return st;
        a->comparing = 1;
    }
    a->writing = c->trajectory;
    return MPM_OK;
}

int run_accuracy_open(RunAccuracy *a, const char *out_dir, const Scene *sc)
{
    if (!a->writing) return MPM_OK;
    return trajectory_writer_open(&a->writer, out_dir, sc->name, sc->dx, sc->particles.n);
}

void *run_accuracy_json(const AccuracyConfig *c, const RunAccuracy *a)
{
    json_t *j = json_object();
    json_object_set_new(j, "error_ref", a->ref ? json_string(error_ref_describe(a->ref)) : json_null());
    json_object_set_new(j, "dt_from", c->dt_from ? json_string(c->dt_from) : json_null());
    json_object_set_new(j, "trajectory_ref", c->trajectory_ref ? json_string(c->trajectory_ref) : json_null());
    json_object_set_new(j, "trajectory", json_boolean(c->trajectory));
    json_object_set_new(
        j, "columns",
        json_pack("{s:s, s:s, s:s, s:s, s:s, s:s, s:s, s:s, s:s, s:s}", "err_h",
                  "steps.csv: ||dv - dv*||_H / ||dv* - dv0||_H, H the BC-projected Hessian (projected tangent) at the "
                  "reference's dv*",
                  "e_gap", "steps.csv: (E(dv) - E(dv*)) / |E(dv0) - E(dv*)|", "err_v_max",
                  "steps.csv: max over nodes |dv - dv*| dt / dx", "ref_solver", "steps.csv: the reference solve's solver",
                  "ref_status", "steps.csv: its status", "ref_s",
                  "steps.csv: its seconds (and the metrics'), in no other timing column", "max_energy_rise",
                  "steps.csv: the largest energy increase a line search accepted (0: none)", "pos_rms",
                  "frames.csv: rms particle position difference to the --trajectory-ref run, in dx", "pos_max",
                  "frames.csv: largest particle position difference, in dx", "vel_rms",
                  "frames.csv: rms particle velocity difference over the reference's rms speed"));
    return j;
}

int run_accuracy_before_step(RunAccuracy *a, Simulation *sim, int step_in_frame, StepWork *w)
{
    if (a->ref) {
        error_ref_clear(a->ref);
        w->after_solve = error_ref_measure;
        w->after_solve_ctx = a->ref;
    }
    if (a->replaying) return dt_replay_next(&a->replay, sim->frame, step_in_frame, &sim->dt_next);
    return MPM_OK;
}

/* A number (or an empty field when not finite) and the comma after it. */
static void field(FILE *f, const char *fmt, double v)
{
    if (isfinite(v)) fprintf(f, fmt, v);
    fputc(',', f);
}

void run_accuracy_step_fields(FILE *f, const RunAccuracy *a)
{
    const StepError *e = a->ref ? error_ref_last(a->ref) : NULL;
    if (!e || !e->valid) {
        fputs(",,,,,,", f);
        return;
    }
    field(f, "%.9e", e->err_h);
    field(f, "%.9e", e->e_gap);
    field(f, "%.9e", e->err_v_max);
    csv_write_name(f, e->ref_solver);
    fprintf(f, ",%s,%.6f,", solve_status_name(e->ref_status), e->ref_s);
}

int run_accuracy_frame_end(RunAccuracy *a, const Simulation *sim, int frame, int steps, int complete, FILE *f)
{
    int st = MPM_OK;
    TrajectoryError te = {NAN, NAN, NAN};
    if (complete && a->replaying) st = dt_replay_frame_end(&a->replay, frame, steps);
    if (!st && complete && a->writing) st = trajectory_write_frame(&a->writer, frame, sim->t, &sim->p);
    if (!st && complete && a->comparing) st = trajectory_compare_frame(&a->reader, frame, &sim->p, sim->scene->dx, &te);
    field(f, "%.9e", te.pos_rms);
    field(f, "%.9e", te.pos_max);
    field(f, "%.9e", te.vel_rms);
    return st;
}

void run_accuracy_free(RunAccuracy *a)
{
    error_ref_destroy(a->ref);
    dt_replay_free(&a->replay);
    trajectory_writer_close(&a->writer);
    trajectory_reader_close(&a->reader);
    memset(a, 0, sizeof *a);
}
