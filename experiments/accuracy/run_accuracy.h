/* The accuracy attachments of a run (SPEC 11; docs/accuracy.md), kept out
 * of the run loop: --error-ref (per-step error against a reference solve,
 * error_ref.h), --dt-from (the reference run's dt sequence, dt_replay.h),
 * --trajectory (write OUT/trajectory.bin) and --trajectory-ref (the
 * trajectory error per frame, trajectory.h). Each is off unless asked; the
 * CSV columns are there always, empty when off. */
#ifndef MPM_RUN_ACCURACY_H
#define MPM_RUN_ACCURACY_H

#include <stdio.h>

#include "core/scene_description.h"
#include "experiments/driver/time_step.h"
#include "experiments/accuracy/dt_replay.h"
#include "experiments/accuracy/error_ref.h"
#include "experiments/accuracy/trajectory.h"

typedef struct {
    const char *error_ref;      /* SOLVER[:eps] | auto[:eps] | NULL */
    const char *dt_from;        /* reference run directory | NULL */
    const char *trajectory_ref; /* reference run directory | NULL */
    int trajectory;             /* write OUT/trajectory.bin */
} AccuracyConfig;

typedef struct {
    ErrorRef *ref;
    DtReplay replay;
    int replaying;
    TrajectoryWriter writer;
    TrajectoryReader reader;
    int writing, comparing;
} RunAccuracy;

/* Validates the flags without work (the reference solvers, the directories
 * exist). */
int run_accuracy_check(const AccuracyConfig *c);
/* Creates the reference solvers (and starts their libraries), before the
 * scene is loaded. */
int run_accuracy_create(const AccuracyConfig *c, RunAccuracy *a);
/* With the scene loaded and before the output folder is made: checks the
 * reference runs against it (scene, particles, frames). */
int run_accuracy_bind(const AccuracyConfig *c, const Scene *sc, int frames, RunAccuracy *a);
/* After the output folder is made: opens OUT/trajectory.bin. */
int run_accuracy_open(RunAccuracy *a, const char *out_dir, const Scene *sc);

/* run.json's "accuracy" object. */
void *run_accuracy_json(const AccuracyConfig *c, const RunAccuracy *a);

/* Before each step: the replayed dt (sim->dt_next), time_step_run's after-solve
 * hook (the reference solve) in w, the last step's errors cleared. */
int run_accuracy_before_step(RunAccuracy *a, Simulation *sim, int step_in_frame, StepWork *w);

/* The steps.csv columns before `reason` (header, and one step's fields,
 * each followed by a comma), the frames.csv ones likewise. */
extern const char *const run_accuracy_step_header;
extern const char *const run_accuracy_frame_header;
void run_accuracy_step_fields(FILE *f, const RunAccuracy *a);
/* At a frame's end (frame = frames.csv's frame, steps = its steps,
 * complete = the frame ran to its end, not cut short by a stop): the replay
 * check, the trajectory record, the comparison fields into f (empty for an
 * incomplete frame). */
int run_accuracy_frame_end(RunAccuracy *a, const Simulation *sim, int frame, int steps, int complete, FILE *f);

void run_accuracy_free(RunAccuracy *a);

#endif
