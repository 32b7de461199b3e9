/* Replaying a reference run's dt sequence (dt_replay.h). */
#include "experiments/accuracy/dt_replay.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "experiments/io/csv_table.h"

int reference_run_check(const char *flag, const char *dir, const char *scene, size_t particles)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/run.json", dir);
    json_error_t err;
    json_t *run = json_load_file(path, 0, &err);
    if (!run) return mpm_error(MPM_EINPUT, "%s %s: cannot read %s (not a run directory?)", flag, dir, path);
    json_t *js = json_object_get(run, "scene"), *jp = json_object_get(run, "particles");
    const char *rs = json_is_string(js) ? json_string_value(js) : "?";
    long long rp = json_is_integer(jp) ? (long long)json_integer_value(jp) : -1;
    int st = MPM_OK;
    if (strcmp(rs, scene) != 0)
        st = mpm_error(MPM_EINPUT, "%s %s: the reference is scene \"%s\", this run is scene \"%s\"", flag, dir, rs,
                       scene);
    else if (rp != (long long)particles)
        st = mpm_error(MPM_EINPUT,
                       "%s %s: the reference starts with %lld particles, this run with %zu (another --scale or --set?)",
                       flag, dir, rp, particles);
    json_decref(run);
    return st;
}

int dt_replay_load(DtReplay *r, const char *dir, const char *scene, size_t particles, int frames)
{
    memset(r, 0, sizeof *r);
    snprintf(r->dir, sizeof r->dir, "%s", dir);
    int st = reference_run_check("--dt-from", dir, scene, particles);
    if (st) return st;
    char path[1200];
    snprintf(path, sizeof path, "%s/steps.csv", dir);
    CsvTable t;
    if ((st = csv_read(path, &t))) return st;
    int cf = csv_col(&t, "frame"), cs = csv_col(&t, "step"), cd = csv_col(&t, "dt"), cst = csv_col(&t, "status");
    if (cf < 0 || cs < 0 || cd < 0) {
        csv_free(&t);
        return mpm_error(MPM_EINPUT, "--dt-from %s: %s has no frame, step and dt columns", dir, path);
    }
    r->frame = malloc(sizeof(int) * (size_t)(t.n_rows + 1));
    r->step = malloc(sizeof(int) * (size_t)(t.n_rows + 1));
    r->dt = malloc(sizeof(double) * (size_t)(t.n_rows + 1));
    if (!r->frame || !r->step || !r->dt) {
        csv_free(&t);
        return mpm_error(MPM_EINTERNAL, "out of memory (--dt-from)");
    }
    for (int i = 0; i < t.n_rows && !st; ++i) {
        char *end = NULL;
        const char *sd = csv_get(&t, i, cd);
        r->frame[i] = atoi(csv_get(&t, i, cf));
        r->step[i] = atoi(csv_get(&t, i, cs));
        r->dt[i] = strtod(sd, &end);
        if (!sd[0] || *end || !(r->dt[i] > 0.0))
            st = mpm_error(MPM_EINPUT, "--dt-from %s: %s row %d: dt \"%s\" is not a positive number", dir, path, i + 2,
                           sd);
        else if (i > 0 && !(r->frame[i] == r->frame[i - 1] ? r->step[i] == r->step[i - 1] + 1
                                                            : r->frame[i] == r->frame[i - 1] + 1 && r->step[i] == 0))
            st = mpm_error(MPM_EINPUT, "--dt-from %s: %s row %d: frame %d step %d does not follow frame %d step %d",
                           dir, path, i + 2, r->frame[i], r->step[i], r->frame[i - 1], r->step[i - 1]);
        else if (cst >= 0 && !strcmp(csv_get(&t, i, cst), "failed"))
            /* a failed step may not have advanced the reference: what came after is not a trajectory */
            st = mpm_error(MPM_EINPUT, "--dt-from %s: %s row %d: frame %d step %d failed in the reference", dir, path,
                           i + 2, r->frame[i], r->step[i]);
        r->n = i + 1;
    }
    csv_free(&t);
    if (st) return st;
    r->frames = r->n ? r->frame[r->n - 1] + 1 : 0;
    /* a last frame cut short (a time limit) shows as a missing step during the replay */
    if (frames > r->frames)
        return mpm_error(MPM_EINPUT, "--dt-from %s: the reference has %d frames, this run asks for %d", dir, r->frames,
                         frames);
    return MPM_OK;
}

int dt_replay_next(DtReplay *r, int frame, int step, double *dt)
{
    if (r->next >= r->n || r->frame[r->next] != frame || r->step[r->next] != step)
        return mpm_error(MPM_EINPUT, "--dt-from %s: the reference has no step %d in frame %d where this run is", r->dir,
                         step, frame);
    *dt = r->dt[r->next++];
    return MPM_OK;
}

int dt_replay_frame_end(const DtReplay *r, int frame, int steps)
{
    int ref = 0;
    for (int i = 0; i < r->n; ++i) ref += r->frame[i] == frame;
    if (ref != steps)
        return mpm_error(MPM_EINPUT, "--dt-from %s: frame %d took %d steps here but %d in the reference", r->dir, frame,
                         steps, ref);
    return MPM_OK;
}

void dt_replay_free(DtReplay *r)
{
    free(r->frame);
    free(r->step);
    free(r->dt);
    memset(r, 0, sizeof *r);
}
