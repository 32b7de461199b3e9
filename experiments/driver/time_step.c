/* One time step (time_step.h). */
#include "experiments/driver/time_step.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/step_phases.h"

/* A numerical breakdown outside the solver: the step's failed status. */
static int breakdown(int status, SolveStats *ss)
{
    if (status != MPM_ENUMERIC) return status;
    ss->status = SOLVE_FAILED;
    snprintf(ss->reason, sizeof ss->reason, "%s", mpm_last_error());
    mpm_clear_error();
    return MPM_OK;
}

static int reserve(StepWork *w, int n)
{
    if (n <= w->cap) return MPM_OK;
    int cap = n + n / 4 + 256;
    double *q = realloc(w->dv, sizeof(double) * 3 * (size_t)cap);
    if (!q) return mpm_error(MPM_EINTERNAL, "out of memory: dv (%d nodes)", n);
    w->dv = q;
    w->cap = cap;
    return MPM_OK;
}

/* The driver's own events: the whole step, and the after-solve hook inside
 * it (its time is in no column), beside the step phases' table. */
static int step_events(EventId phase[STEP_PHASES], EventId *step, EventId *after_solve)
{
    int st = step_phases_register(phase);
    if (!st) st = event_register("time_step", EVENT_NONE, step);
    if (!st) st = event_register("after_solve", *step, after_solve);
    return st;
}

/* step_begin, the solve and step_end with the log open on `step`; every
 * event this opens is closed on every path. */
static int advance(Simulation *sim, Solver *solver, const SolveSettings *set, StepWork *w, EventLog *log,
                   const EventId *phase, EventId after_solve, IterHook hook, void *hook_ctx, int apply_failed,
                   SolveStats *ss, StepInfo *info)
{
    int status = event_log_begin(log, phase[STEP_P2G]);
    if (status) return status;
    int begun = step_begin(sim);
    if ((status = event_log_end(log, phase[STEP_P2G]))) return status;
    info->dt = sim->dt;
    if (begun) return breakdown(begun, ss);
    info->t = sim->t;
    int n = sim->pb.n_nodes;
    info->active_nodes = n;
    if ((status = reserve(w, n))) return status;
    problem_initial_guess(&sim->pb, w->dv);
    if ((status = solver_solve(solver, &sim->pb, set, w->dv, ss, log, hook, hook_ctx))) return status;
    if (ss->status == SOLVE_FAILED && !apply_failed) return MPM_OK;
    if (w->after_solve && !(status = event_log_begin(log, after_solve)))
        status = event_log_end_with(log, after_solve, w->after_solve(w->after_solve_ctx, &sim->pb, w->dv));
    if (status) return status;
    if ((status = event_log_begin(log, phase[STEP_G2P]))) return status;
    SolveStats end = {0};
    status = event_log_end_with(log, phase[STEP_G2P], breakdown(step_end(sim, w->dv), &end));
    if (status) return status;
    if (end.status == SOLVE_FAILED) {
        ss->status = SOLVE_FAILED;
        snprintf(ss->reason, sizeof ss->reason, "%s", end.reason);
    } else {
        info->advanced = 1;
    }
    return MPM_OK;
}

int time_step_run(Simulation *sim, Solver *solver, const SolveSettings *set, StepWork *w, IterHook hook,
                  void *hook_ctx, int apply_failed, SolveStats *ss, StepInfo *info)
{
    memset(ss, 0, sizeof *ss);
    memset(info, 0, sizeof *info);
    info->t = sim->t;
    EventLog *log = w->log ? w->log : &solver->log;
    EventId phase[STEP_PHASES], step, after_solve;
    EventTotals before, now;
    int status = step_events(phase, &step, &after_solve);
    if (!status) status = event_log_snapshot(log, &before);
    if (!status) status = event_log_begin(log, step);
    if (status) return status;
    status = event_log_end_with(log, step, advance(sim, solver, set, w, log, phase, after_solve, hook, hook_ctx,
                                                   apply_failed, ss, info));
    if (!status) status = event_log_snapshot(log, &now);
    if (status) return status;
    event_totals_since(&now, &before, &now);
    info->begin_s = now.event[phase[STEP_P2G]].seconds;
    info->end_s = now.event[phase[STEP_G2P]].seconds;
    info->after_solve_s = now.event[after_solve].seconds;
    info->wall_s = now.event[step].seconds - info->after_solve_s;
    return MPM_OK;
}

void time_step_work_free(StepWork *w)
{
    free(w->dv);
    w->dv = NULL;
    w->cap = 0;
}
