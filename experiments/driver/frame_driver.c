/* The frame driver (frame_driver.h). */
#include "experiments/driver/frame_driver.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/event_log.h"
#include "core/error.h"
#include "experiments/driver/progress.h"

typedef struct {
    const FrameDriver *d;
    Progress *progress;
    int frame, step;
    double fraction;
} Iteration;

static void on_iteration(void *ctx, int iter, double elapsed, double residual, double energy)
{
    Iteration *h = ctx;
    if (h->d->iteration) h->d->iteration(h->d->ctx, h->frame, h->step, iter, elapsed, residual, energy);
    progress_update(h->progress, h->fraction, h->frame, h->step, iter, residual, elapsed);
}

static int worse(int a, int b) { return a > b ? a : b; } /* SolveStatus is ordered by severity */

/* The deadline of the next solve: the earlier of the step's and the run's. */
static void set_deadline(const FrameDriver *d, double run_t0, SolveSettings *set, char *why, size_t len)
{
    set->deadline = (Deadline){.reason = why};
    why[0] = '\0';
    if (d->max_step_s > 0) {
        set->deadline = deadline_in(d->max_step_s, why);
        snprintf(why, len, "--max-step-seconds %g", d->max_step_s);
    }
    /* run_t0 is on the clock of deadlines (event_clock) */
    if (d->max_run_s > 0 && (!set->deadline.active || run_t0 + d->max_run_s < set->deadline.at)) {
        set->deadline = (Deadline){.active = 1, .at = run_t0 + d->max_run_s, .reason = why};
        snprintf(why, len, "--max-run-seconds %g", d->max_run_s);
    }
}

int frame_driver_run(const FrameDriver *d, Simulation *sim, Solver *solver, SolveSettings *set, DriveTotals *sum,
                     char *stop_reason, size_t reason_len)
{
    int status = MPM_OK;
    StepWork work = {.dv = NULL, .cap = 0};
    Progress prog;
    const int sampled = d->n_samples > 0, runs = sampled ? d->n_samples : 1;
    progress_init(&prog, sampled ? d->n_samples : d->frames);
    if (!d->progress) prog.enabled = 0;
    Iteration hook = {d, &prog, 0, 0, 0.0};
    char deadline_why[64];
    stop_reason[0] = '\0';
    double run_t0 = event_clock();
    memset(sum, 0, sizeof *sum);
    for (int r = 0; r < runs && !sum->stopped; ++r) {
        int end = d->frames; /* the drive (or this sample) ends when sim->frame reaches it */
        if (sampled) {
            if (d->restore && (status = d->restore(d->ctx, sim, d->sample_frames[r]))) goto done;
            end = d->sample_frames[r] + 1;
        }
        while (sim->frame < end && !sum->stopped) {
            FrameSums f;
            memset(&f, 0, sizeof f);
            f.frame = sim->frame;
            f.status = SOLVE_CONVERGED;
            while (sim->frame == f.frame) {
                hook.frame = f.frame;
                hook.step = f.steps;
                hook.fraction = sampled ? (r + sim->t_in_frame / sim->frame_dt) / d->n_samples
                                        : (f.frame + sim->t_in_frame / sim->frame_dt) / d->frames;
                set_deadline(d, run_t0, set, deadline_why, sizeof deadline_why);
                if (d->before_step && (status = d->before_step(d->ctx, sim, f.frame, f.steps, &work))) goto done;
                SolveStats ss;
                StepInfo si;
                if ((status = time_step_run(sim, solver, set, &work, on_iteration, &hook,
                                            d->on_failure == FAILURE_CONTINUE, &ss, &si)))
                    goto done;
                run_t0 += si.after_solve_s; /* a reference solve is not the run's time */
                if (d->after_step && (status = d->after_step(d->ctx, sim, f.frame, f.steps, &ss, &si))) goto done;
                f.steps++;
                f.outer_iters += ss.outer_iters;
                f.linear_iters += ss.linear_iters;
                f.inner_iters += ss.inner_iters;
                f.wall_s += si.wall_s;
                if (!(ss.residual <= f.max_residual)) f.max_residual = ss.residual; /* NaN included */
                if ((int)ss.status > f.status) snprintf(f.reason, sizeof f.reason, "%s", ss.reason);
                f.status = worse(f.status, ss.status);
                if (!si.advanced) { /* a failure the policy does not (or cannot) go past */
                    snprintf(stop_reason, reason_len, "frame %d step %d failed: %s", f.frame, f.steps - 1, ss.reason);
                    sum->stopped = 1;
                    break;
                }
                int more = sim->frame < end || r + 1 < runs; /* frames left to drive */
                if (d->max_run_s > 0 && more && event_clock() - run_t0 >= d->max_run_s) {
                    /* the run's budget is spent with frames left: this step was the last */
                    snprintf(stop_reason, reason_len, "time limit --max-run-seconds %g reached at frame %d step %d",
                             d->max_run_s, f.frame, f.steps - 1);
                    if (sim->frame == f.frame && f.status < SOLVE_TIMEOUT) { /* the frame is cut short */
                        snprintf(f.reason, sizeof f.reason, "%s", stop_reason);
                        f.status = SOLVE_TIMEOUT;
                    }
                    sum->stopped = 1;
                    break;
                }
            }
            f.completed = sim->frame > f.frame;
            progress_clear(&prog);
            if (d->after_frame && (status = d->after_frame(d->ctx, sim, &f, sum->stopped))) goto done;
            sum->frames++;
            sum->steps += f.steps;
            sum->outer_iters += f.outer_iters;
            sum->linear_iters += f.linear_iters;
            sum->inner_iters += f.inner_iters;
            if (f.max_residual > sum->max_residual) sum->max_residual = f.max_residual;
            sum->worst_status = worse(sum->worst_status, f.status);
            /* the frame the drive would have run next, -1 when none */
            int next = sampled ? (sim->frame < end ? sim->frame : r + 1 < runs ? d->sample_frames[r + 1] : -1)
                               : (sim->frame < d->frames ? sim->frame : -1);
            if (sum->stopped && f.completed && next >= 0) {
                /* the budget ran out exactly at a frame's end: the next frame is
                 * handed over as cut short before its first step, so that its
                 * row, not only stderr, says why the run ended early */
                FrameSums cut = {.frame = next, .status = SOLVE_TIMEOUT};
                snprintf(cut.reason, sizeof cut.reason, "%s", stop_reason);
                if (d->after_frame && (status = d->after_frame(d->ctx, sim, &cut, 1))) goto done;
                sum->worst_status = worse(sum->worst_status, cut.status);
            }
        }
    }
    sum->wall_s = event_clock() - run_t0;
done:
    progress_clear(&prog);
    time_step_work_free(&work);
    return status;
}
