/* The frame driver: simulates frames of time steps (time_step_run:
 * step_begin, the solve, step_end), keeps the per-frame and per-run sums,
 * shows the progress line, applies the time limits and the failure policy,
 * and hands each step and each frame to callbacks. `mpmbench run` writes its
 * CSV rows and table from them (experiments/run/run.c), `mpmbench render`
 * only simulates (render_cmd.c), and a program embedding mpmbench can do
 * the same without any file output: everything advances a simulation
 * through this one loop. */
#ifndef MPM_FRAME_DRIVER_H
#define MPM_FRAME_DRIVER_H

#include "experiments/driver/time_step.h"

/* What the drive does when a step fails (a numerical breakdown: status
 * failed, the reason in SolveStats.reason). */
typedef enum {
    FAILURE_STOP = 0,     /* hand over the step's and the frame's sums, end the drive */
    FAILURE_CONTINUE = 1, /* apply the last accepted iterate and go on, unless the
                             simulation state itself broke (step_begin or step_end
                             failed): then stop as FAILURE_STOP */
} FailurePolicy;

/* The sums of a whole drive. */
typedef struct {
    int frames, steps;          /* frames with at least one step, steps */
    long outer_iters, linear_iters, inner_iters;
    double wall_s, max_residual;
    int worst_status;           /* SolveStatus */
    int stopped;                /* the drive ended early (failure policy or the run's time budget) */
} DriveTotals;

/* The sums of one frame (a frame cut short by a stop has the steps it ran;
 * when the run's time budget ends exactly at a frame's end, the next frame
 * is handed over with no steps, status timeout and the stop's reason). */
typedef struct {
    int frame, steps;
    long outer_iters, linear_iters, inner_iters;
    double wall_s, max_residual;  /* max_residual is NaN when a step's was */
    int status;                   /* the worst SolveStatus of its steps */
    char reason[256];             /* the reason of the step with the worst status */
    int completed;                /* the simulation moved past the frame */
} FrameSums;

typedef struct {
    int frames;              /* simulate until sim->frame reaches it */
    /* n_samples > 0: instead, drive only the frames sample_frames[0..n)
     * (increasing), each alone: restore() puts the state at the start of
     * frame k into sim (a checkpoint), then frame k runs; `frames` is not
     * used. The time budget and the failure policy span all of them. */
    const int *sample_frames;
    int n_samples;
    int (*restore)(void *ctx, Simulation *sim, int frame);
    FailurePolicy on_failure;
    int progress;            /* show the progress line (on a terminal only, never in CI or a pipe) */
    double max_step_s;       /* > 0: each solve's deadline (--max-step-seconds) */
    double max_run_s;        /* > 0: the run's time budget (--max-run-seconds) */
    /* Callbacks, each optional (NULL). A non-zero return ends the drive with
     * that status. */
    /* before each step's time_step_run (w: its dv storage and after-solve hook) */
    int (*before_step)(void *ctx, Simulation *sim, int frame, int step, StepWork *w);
    /* after each step, with its statistics (time of the after-solve hook excluded) */
    int (*after_step)(void *ctx, const Simulation *sim, int frame, int step, const SolveStats *ss,
                      const StepInfo *si);
    /* after each frame, the frame's sums; stopping: the drive ends after it */
    int (*after_frame)(void *ctx, const Simulation *sim, const FrameSums *f, int stopping);
    /* every outer iteration of every solve (iters.csv) */
    void (*iteration)(void *ctx, int frame, int step, int iter, double elapsed, double residual, double energy);
    void *ctx;
} FrameDriver;

/* Drives sim from its current frame up to d->frames. sum gets the totals;
 * stop_reason (when sum->stopped) why the drive ended early: a step that
 * failed and was not applied (or broke the state), or the run's time
 * budget. MPM_OK unless a step or a callback returned an error. */
int frame_driver_run(const FrameDriver *d, Simulation *sim, Solver *solver, SolveSettings *set, DriveTotals *sum,
                     char *stop_reason, size_t reason_len);

#endif
