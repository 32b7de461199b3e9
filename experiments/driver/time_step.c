/* One time step (time_step.h). */
#include "experiments/driver/time_step.h"

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

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

int time_step_run(Simulation *sim, Solver *solver, const SolveSettings *set, StepWork *w, IterHook hook,
                  void *hook_ctx, int apply_failed, SolveStats *ss, StepInfo *info)
{
    int status;
    memset(ss, 0, sizeof *ss);
    memset(info, 0, sizeof *info);
    double t0 = omp_get_wtime();
    info->t = sim->t;
    status = step_begin(sim);
    double t1 = omp_get_wtime();
    info->begin_s = t1 - t0;
    info->dt = sim->dt;
    if (status) {
        info->wall_s = info->begin_s;
        return breakdown(status, ss);
    }
    info->t = sim->t;
    int n = sim->pb.n_nodes;
    info->active_nodes = n;
    if ((status = reserve(w, n))) return status;
    problem_initial_guess(&sim->pb, w->dv);
    if ((status = solver_solve(solver, &sim->pb, set, w->dv, ss, NULL, hook, hook_ctx))) return status;
    double t2 = omp_get_wtime();
    if (ss->status != SOLVE_FAILED || apply_failed) {
        if (w->after_solve) {
            if ((status = w->after_solve(w->after_solve_ctx, &sim->pb, w->dv))) return status;
            info->after_solve_s = omp_get_wtime() - t2;
        }
        SolveStats end = {0};
        status = breakdown(step_end(sim, w->dv), &end);
        if (status) return status;
        if (end.status == SOLVE_FAILED) {
            ss->status = SOLVE_FAILED;
            snprintf(ss->reason, sizeof ss->reason, "%s", end.reason);
        } else {
            info->advanced = 1;
        }
    }
    double t3 = omp_get_wtime();
    info->wall_s = t3 - t0 - info->after_solve_s;
    info->end_s = t3 - t2 - info->after_solve_s;
    return MPM_OK;
}

void time_step_work_free(StepWork *w)
{
    free(w->dv);
    w->dv = NULL;
    w->cap = 0;
}
