/* Replaying a reference run's time steps (`run --dt-from RUN_DIR`, SPEC 11):
 * the CFL dt depends on the velocities, so two solvers would take different
 * dt sequences; replaying the reference's (RUN_DIR/steps.csv, columns
 * frame, step, dt, printed with 17 significant digits so they read back as
 * the same doubles) makes the trajectory difference solver error only.
 *
 * The reference must be the same scene with the same initial particle count
 * (RUN_DIR/run.json "scene" and "particles"; MPM_EINPUT naming both
 * otherwise) and have every step of the frames this run asks for. During
 * the run each step takes the reference's dt for the same (frame, step), and
 * each frame must end after the same number of steps as the reference's
 * (else MPM_EINPUT: the replay lost step). */
#ifndef MPM_DT_REPLAY_H
#define MPM_DT_REPLAY_H

#include <stddef.h>

typedef struct {
    char dir[1024];
    int n;              /* steps */
    int *frame, *step;  /* per step */
    double *dt;
    int frames;         /* frames with at least one step */
    int next;           /* the next step to hand out */
} DtReplay;

/* The identity check of a reference run directory (run.json): used by
 * --dt-from and --trajectory-ref alike. */
int reference_run_check(const char *flag, const char *dir, const char *scene, size_t particles);

/* Loads RUN_DIR/steps.csv and checks it covers `frames` frames. */
int dt_replay_load(DtReplay *r, const char *dir, const char *scene, size_t particles, int frames);
/* The dt of step `step` of frame `frame` (the next one in order). */
int dt_replay_next(DtReplay *r, int frame, int step, double *dt);
/* Frame `frame` ended after `steps` steps: the reference's did too? */
int dt_replay_frame_end(const DtReplay *r, int frame, int steps);
void dt_replay_free(DtReplay *r);

#endif
