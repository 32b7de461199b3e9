/* The frame driver: simulates frames of time steps (run_step: step_begin,
 * the solve, step_end), keeps the per-frame and per-run sums, shows the
 * progress line, applies the time limits and the failure policy, and hands
 * each step and each frame to callbacks. `mpmbench run` writes its CSV rows
 * and table from them (run.c), `mpmbench render` only simulates
 * (render_cmd.c): both advance the simulation through this one loop. */
#ifndef MPM_FRAME_DRIVER_H
#define MPM_FRAME_DRIVER_H

#include "experiments/run/run.h"

/* The sums of one frame (a frame cut short by a stop has the steps it ran). */
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
    int apply_failed;        /* a failed solve is applied (--on-failure continue) */
    double max_step_s;       /* > 0: each solve's deadline (--max-step-seconds) */
    double max_run_s;        /* > 0: the run's time budget (--max-run-seconds) */
    /* Callbacks, each optional (NULL). A non-zero return ends the drive with
     * that status. */
    /* before each step's run_step (w: its dv storage and after-solve hook) */
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

/* Drives sim from its current frame up to d->frames. sum gets the totals
 * (frames, steps, iterations, wall_s, max_residual, worst_status, stopped);
 * stop_reason (when sum->stopped) why the drive ended early: a step that
 * failed and was not applied (or broke the state), or the run's time
 * budget. MPM_OK unless a step or a callback returned an error. */
int frame_driver_run(const FrameDriver *d, Simulation *sim, Solver *solver, SolveSettings *set, RunSummary *sum,
                     char *stop_reason, size_t reason_len);

#endif
