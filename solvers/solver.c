#include "solvers/solver.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

void solve_settings_default(SolveSettings *s)
{
    memset(s, 0, sizeof *s);
    s->eps = SOLVE_EPS_DEFAULT;
    s->max_outer = 10000;
    s->max_linear = 10000;
    s->max_halvings = 60;
}

int solve_settings_check(const SolveSettings *s)
{
    if (!(s->eps > 0.0) || !isfinite(s->eps))
        return mpm_error(MPM_EINPUT, "--eps %g: expected a positive number", s->eps);
    if (s->eps < SOLVE_EPS_MIN)
        return mpm_error(MPM_EINPUT,
                         "--eps %g: below %.3g, the smallest CN residual double precision resolves (DBL_EPSILON / 24)",
                         s->eps, SOLVE_EPS_MIN);
    if (s->max_outer < 1) return mpm_error(MPM_EINPUT, "--max-outer %d: expected >= 1", s->max_outer);
    if (s->max_linear < 1) return mpm_error(MPM_EINPUT, "--max-linear %d: expected >= 1", s->max_linear);
    if (s->max_halvings < 0) return mpm_error(MPM_EINPUT, "max_halvings %d: expected >= 0", s->max_halvings);
    return MPM_OK;
}

int solver_create(const char *name, const OuterMethodOps *outer, const InvApproxOps *inverse, const SolverOptions *opts,
                  Solver **out)
{
    *out = NULL;
    Solver *s = calloc(1, sizeof *s);
    if (!s) return mpm_error(MPM_EINTERNAL, "out of memory creating solver %s", name);
    snprintf(s->name, sizeof s->name, "%s", name);
    if (opts) s->opts = *opts;
    int st = step_phases_register(s->phase);
    const char *ls = solver_opt_string(&s->opts, "linesearch", "halving");
    const char *stop = solver_opt_string(&s->opts, "stop", "cn");
    s->stall_iters = solver_opt_int(&s->opts, "stall_iters", 20, 1, 1000000, &st);
    if (!st && !(s->ls = line_search_find(ls)))
        st = mpm_error(MPM_EINPUT, "solver option linesearch=%s: unknown line search (see: mpmbench list solvers)", ls);
    if (!st && !(s->stop = stop_rule_find(stop)))
        st = mpm_error(MPM_EINPUT, "solver option stop=%s: unknown stopping rule (see: mpmbench list solvers)", stop);
    s->stop_tol = NAN;
    if (!st && s->stop->tol_key) {
        s->stop_tol = solver_opt_number(&s->opts, s->stop->tol_key, s->stop->tol_default, &st);
        if (!st && !(s->stop_tol > 0.0))
            st = mpm_error(MPM_EINPUT, "solver option %s=%g: expected a positive number", s->stop->tol_key, s->stop_tol);
    }
    if (!st) st = outer->create(&s->opts, &s->outer);
    if (!st) s->outer->ops = outer;
    if (!st) st = inv_create(inverse, &s->opts, &s->inv);
    if (!st && (s->inv->caps & INV_NEEDS_HESSIAN) && !s->outer->assembled)
        st = mpm_error(MPM_EINPUT,
                       "solver %s: inverse approximation '%s' needs the assembled Hessian, which outer method '%s' "
                       "does not build (matrix-free)",
                       name, inverse->name, outer->name);
    if (!st) st = solver_opts_check_used(&s->opts, name);
    if (st) {
        solver_destroy(s);
        return st;
    }
    *out = s;
    return MPM_OK;
}

int solver_solve(Solver *s, StepProblem *pb, const SolveSettings *set, double *dv, SolveStats *st, EventLog *log,
                 IterHook hook, void *hook_ctx)
{
    memset(st, 0, sizeof *st);
    if (!log) log = &s->log;
    EventTotals before, after;
    int status = event_log_snapshot(log, &before);
    if (status) return status;
    SolveCtx c = {
        .pb = pb,
        .inv = s->inv,
        .ls = s->ls,
        .stop = s->stop,
        .stop_tol = isnan(s->stop_tol) ? set->eps : s->stop_tol,
        .stall_iters = s->stall_iters,
        .set = set,
        .hook = hook,
        .hook_ctx = hook_ctx,
        .log = log,
        .best_energy = INFINITY,
        .best_residual = INFINITY,
    };
    memcpy(c.phase, s->phase, sizeof c.phase);
    if ((status = event_log_begin(log, s->phase[STEP_SOLVE]))) return status;
    EventLog *inv_log = s->inv->log; /* the inverse approximation times into this solve's log */
    s->inv->log = log;
    long inner0 = inv_inner_iters(s->inv);
    inv_begin_solve(s->inv);
    status = s->outer->ops->solve(s->outer, &c, dv, st);
    st->inner_iters = inv_inner_iters(s->inv) - inner0;
    s->inv->log = inv_log;
    int log_status = event_log_end(log, s->phase[STEP_SOLVE]);
    int snapshot_status = event_log_snapshot(log, &after);
    if (!log_status) log_status = snapshot_status;
    event_totals_since(&after, &before, &after);
    st->assemble_s = step_phase_seconds(&after, s->phase, STEP_ASSEMBLE);
    st->setup_s = step_phase_seconds(&after, s->phase, STEP_SETUP);
    st->linesearch_s = step_phase_seconds(&after, s->phase, STEP_LINESEARCH);
    /* the direction (Krylov solves, two-loop recursion) and the stopping
     * tests: the solve less the phases above */
    st->solve_s = step_phase_seconds(&after, s->phase, STEP_SOLVE);
    if (status == MPM_ENUMERIC) {
        /* a breakdown of this step, not of the program: the step's status */
        st->status = SOLVE_FAILED;
        snprintf(st->reason, sizeof st->reason, "%s", mpm_last_error());
        mpm_clear_error();
        status = MPM_OK;
    }
    return status ? status : log_status;
}

/* The events under `parent` with calls in t, in registration order, each
 * followed by its own sub-events one level deeper. */
static void print_events(FILE *f, const EventTotals *t, EventId parent, int depth)
{
    for (EventId e = 0; e < event_count(); ++e) {
        if (event_parent(e) != parent || t->event[e].calls == 0) continue;
        fprintf(f, "  %*s%-*s %10.4f s %8ld calls\n", 2 * depth, "", 28 - 2 * depth, event_name(e),
                t->event[e].seconds, t->event[e].calls);
        print_events(f, t, e, depth + 1);
    }
}

void solver_view(const Solver *s, FILE *f, InvView *inv_view_out)
{
    if (f) {
        fprintf(f, "solver %s: outer method %s x inverse approximation %s; line search %s; stop %s", s->name,
                s->outer->ops->name, s->inv->ops->name, s->ls->name, s->stop->name);
        if (!isnan(s->stop_tol)) fprintf(f, " (%s = %g)", s->stop->tol_key, s->stop_tol);
        fprintf(f, "; stalled after %d iterations without progress\n", s->stall_iters);
        if (s->outer->ops->view) s->outer->ops->view(s->outer, f);
    }
    inv_view(s->inv, f, inv_view_out);
    if (!f) return;
    const EventTotals *t = &s->log.totals;
    int any = 0;
    for (EventId e = 0; e < event_count(); ++e) any |= t->event[e].calls > 0;
    if (!any) return;
    fprintf(f, "events of the solver's own log (seconds over every solve; a sub-phase under its phase):\n");
    print_events(f, t, EVENT_NONE, 0);
}

void solver_destroy(Solver *s)
{
    if (!s) return;
    if (s->outer) s->outer->ops->destroy(s->outer);
    inv_destroy(s->inv);
    free(s);
}
