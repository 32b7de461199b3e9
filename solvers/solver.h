/* A solver = an outer method x an inverse approximation x strategies x
 * options (docs/design.md, "the one idea"). This file composes and runs the parts;
 * which parts exist by name is experiments/run/registry.c's business (the only
 * file that knows every implementation), so solvers/ knows no adapter. */
#ifndef MPM_SOLVER_H
#define MPM_SOLVER_H

#include <float.h>

#include "core/event_log.h"
#include "core/step_phases.h"
#include "solvers/inverse_approx.h"
#include "solvers/outer_method.h"

/* The smallest CN tolerance the run accepts. The CN residual (SPEC 4) is the
 * gradient divided by kappa_i = 24 dx^2 dt abar_i. A change of F_p by one
 * unit in the last place of F ~ I, i.e. a strain of DBL_EPSILON, changes the
 * stress by at most abar DBL_EPSILON and the node force by about
 * dt dx^2 abar DBL_EPSILON (sum_p V_p |grad w_ip| ~ dx^2), hence the scaled
 * residual by about DBL_EPSILON / 24: below that, dv cannot be refined by any
 * representable change of F, and the test compares rounding noise. */
#define SOLVE_EPS_MIN (DBL_EPSILON / 24.0)

/* The CN tolerance when none is given (SPEC 4; HOT's). The one place of this
 * value: the run settings table prints it in --help as written here. */
#define SOLVE_EPS_DEFAULT 1e-7

/* MPM_EINPUT with one line naming the setting when a value is out of range
 * (eps below SOLVE_EPS_MIN, non-positive caps). */
int solve_settings_check(const SolveSettings *s);
void solve_settings_default(SolveSettings *s);

typedef struct Solver {
    char name[96];              /* preset name or the spec, for messages */
    OuterMethod *outer;
    InvApprox *inv;
    const LineSearchOps *ls;
    const StopRuleOps *stop;
    double stop_tol;            /* NAN: the run's eps (rule "cn") */
    int stall_iters;
    SolverOptions opts;         /* every option consulted, with the value in effect */
    EventId phase[STEP_PHASES]; /* the step phases' events, registered by solver_create */
    EventLog log;               /* the solver's own event log: solver_solve times into it when
                                   not handed one; solver_view prints it */
} Solver;

/* Creates outer x inverse with the options (consumed: a key no part reads is
 * an error). The generic options read here: linesearch (halving), stop (cn),
 * its tolerance key (l2: tau), stall_iters (20). An inverse approximation
 * needing the assembled matrix with a matrix-free outer method is refused
 * with one line naming both. Needs no step problem. */
int solver_create(const char *name, const OuterMethodOps *outer, const InvApproxOps *inverse, const SolverOptions *opts,
                  Solver **out);
/* Minimises the step problem from dv (in: initial guess, out: the last
 * accepted iterate). A numerical breakdown inside (MPM_ENUMERIC) becomes
 * st->status failed with the message as st->reason and returns MPM_OK; other
 * errors are returned.
 *
 * Timing: the solve and its phases (core/step_phases.h: solve, assemble,
 * setup, linesearch; and the inverse approximation's apply and its
 * sub-phases, e.g. multigrid's) are events of `log`, which the solver uses
 * only during the call; NULL: the solver's own (s->log). A caller that
 * times a whole step hands its log here and times P2G and G2P into the same
 * one. st's phase timers are this solve's difference of the log. */
int solver_solve(Solver *s, StepProblem *pb, const SolveSettings *set, double *dv, SolveStats *st, EventLog *log,
                 IterHook hook, void *hook_ctx);
/* Prints the composition, the parts' views and the events of the solver's
 * own log to f (when not NULL) and returns the inverse approximation's view
 * (when not NULL). */
void solver_view(const Solver *s, FILE *f, InvView *inv_view);
void solver_destroy(Solver *s);

#endif
