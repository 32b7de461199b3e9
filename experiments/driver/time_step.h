/* One time step of a simulation with a solver: step_begin (P2G, the step
 * problem), the initial guess, the solve, step_end (G2P, ...), timed by
 * phase through the event log (core/event_log.h). Everything that advances a simulation goes through time_step_run:
 * the frame driver, and tests that drive single steps. */
#ifndef MPM_TIME_STEP_H
#define MPM_TIME_STEP_H

#include "core/step.h"
#include "solvers/solver.h"

/* The storage and hook of a sequence of steps. dv grows with the grid and
 * persists across calls (free it with time_step_work_free). */
typedef struct StepWork {
    double *dv;
    int cap;
    /* where the step's phases are timed (core/step_phases.h: P2G, the solve's
     * phases, G2P, and the whole step): a caller's log that records a whole
     * run; NULL: the solver's own (Solver.log) */
    EventLog *log;
    /* optional (NULL = none): called after the solve and before step_end with
     * the step problem and the solver's dv, when the step is applied (the
     * reference solve of --error-ref). Its time is in no timing column
     * (StepInfo.after_solve_s); it must leave the problem's iterate cache at dv. */
    int (*after_solve)(void *ctx, StepProblem *pb, const double *dv);
    void *after_solve_ctx;
} StepWork;

typedef struct {
    double t, dt;               /* the step's start time and length */
    int active_nodes;
    double wall_s;              /* the whole step */
    double begin_s, end_s;      /* step_begin (P2G, BCs) and step_end (G2P, ...) */
    double after_solve_s;       /* the after-solve hook, not in wall_s or end_s */
    int advanced;               /* step_end ran: the simulation moved to the next step */
} StepInfo;

/* A numerical breakdown (MPM_ENUMERIC from step_begin, the solve or
 * step_end) is not an error here: ss->status is failed with the message in
 * ss->reason, and MPM_OK is returned. A failed solve is applied (step_end
 * with the last accepted iterate) only when apply_failed is set. Other
 * errors are returned. */
int time_step_run(Simulation *sim, Solver *solver, const SolveSettings *set, StepWork *w, IterHook hook,
                  void *hook_ctx, int apply_failed, SolveStats *ss, StepInfo *info);

void time_step_work_free(StepWork *w);

#endif
