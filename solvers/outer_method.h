/* The outer-method interface (docs/design.md, "the one idea"): projected Newton,
 * L-BFGS, ... as objects with an ops table and a private context, registered
 * by name in experiments/run/registry.c like the inverse approximations.
 *
 * A method minimises the step problem's incremental potential from dv. It is
 * handed, in a SolveCtx, everything that is not its own algorithm: the
 * inverse approximation, the line-search strategy (solvers/line_search.h)
 * and the stopping rule (solvers/stop_rule.h) chosen by options, the caps and
 * time limit, and the iteration hook. It calls the helpers below so that
 * every method stops, times and counts by the same rules; a method never
 * reads a clock or counts work itself (the way PETSc times KSPSolve and
 * PCApply in the wrapper, not in each implementation). The wrappers time
 * the step phases of core/step_phases.h through the solve's event log
 * (SolveCtx.log), and the deadline is a value of the settings that
 * deadline_passed() tests:
 *  - solve_should_stop() at the top of every iteration (convergence, the
 *    outer cap, the time limit, stagnation, non-finite values);
 *  - solve_direction_converged() once the iteration's search direction is
 *    known, before the line search (rules that decide on the direction,
 *    stop=decrement; the method does not know which rule it has);
 *  - solve_energy() / solve_gradient() / solve_evaluate(),
 *    solve_assemble(), solve_setup_inverse(), solve_line_search(),
 *    solve_pcg() and solve_minres() for the phases timed and the work
 *    counted in SolveStats; solver_solve() times the whole solve as the
 *    event "solve" and charges its remainder (the direction: Krylov solves,
 *    the two-loop recursion) to solve_s.
 * Adding an outer method is one new file defining its OuterMethodOps and one
 * line in experiments/run/registry.c; tests/conformance/test_conformance.c then checks it
 * (when it claims OUTER_TO_TOLERANCE: reaches eps, honours the cap with
 * status capped, stalls at an unreachable tolerance; when it claims
 * OUTER_DESCENT: never accepts an energy increase).
 *
 * Statistics contract (SolveStats, docs/solvers.md "Statistics contract"):
 *  - outer_iters: iterations of the outer method;
 *  - linear_iters: PCG iterations of the outer method's own linear solves
 *    (PN's H p = -g; 0 for L-BFGS, which solves none);
 *  - inner_iters: iterations inside the inverse approximation (coarsest-level
 *    PCG of a V-cycle, LBFGS-H's PCG), counted by the solver layer;
 *  - phase timers, together covering the solve, filled from the solve's
 *    event log (the difference of its snapshots before and after):
 *    assemble_s (tangent stiffness, Hessian assembly or matrix-free
 *    diagonal), setup_s (inverse approximation setup), linesearch_s (every
 *    energy and gradient evaluation: the initial point, the line-search
 *    trials, the gradient at the accepted point) and solve_s, the remainder
 *    (the direction: PCG, two-loop recursion, and the stopping tests). */
#ifndef MPM_OUTER_METHOD_H
#define MPM_OUTER_METHOD_H

#include <stdint.h>
#include <stdio.h>

#include "core/bsr.h"
#include "core/deadline.h"
#include "core/event_log.h"
#include "core/problem.h"
#include "core/step_phases.h"
#include "solvers/inverse_approx.h"
#include "solvers/krylov/minres.h"
#include "solvers/krylov/pcg.h"
#include "solvers/line_search.h"
#include "solvers/solver_options.h"
#include "solvers/stop_rule.h"

/* Ordered by severity (a frame reports its worst step). */
typedef enum { SOLVE_CONVERGED = 0, SOLVE_CAPPED, SOLVE_STALLED, SOLVE_TIMEOUT, SOLVE_FAILED } SolveStatus;
const char *solve_status_name(SolveStatus s);

typedef struct {
    double eps;           /* CN tolerance (SPEC 4), default SOLVE_EPS_DEFAULT (solver.h) */
    int max_outer;        /* 10000 */
    int max_linear;       /* 10000: PCG iterations per linear solve */
    int max_halvings;     /* 60 */
    Deadline deadline;    /* past it the solve stops as timeout (none: zero-initialised) */
} SolveSettings;

typedef struct {
    int outer_iters;
    long linear_iters;
    long inner_iters;
    int ls_evals;         /* energy evaluations */
    double residual;      /* scaled CN residual at the returned dv */
    SolveStatus status;
    char reason[256];     /* why the solve did not converge ("" when it did) */
    double assemble_s, setup_s, solve_s, linesearch_s;
    /* the largest E(accepted) - E(previous iterate) over the line searches of
     * the solve (solve_line_search), 0 when none rose: > 0 means a strategy
     * accepted an energy increase (the stress suite's check) */
    double energy_increase_max;
    int64_t hessian_blocks;
    size_t hessian_bytes;
} SolveStats;

/* Called at every outer iteration with the CN residual and energy. */
typedef void (*IterHook)(void *ctx, int iter, double elapsed_s, double residual, double energy);

enum {
    OUTER_DESCENT = 1u << 0,      /* never accepts an iterate of higher energy */
    OUTER_TO_TOLERANCE = 1u << 1, /* iterates until the stopping rule holds (not, e.g., a
                                     semi-implicit method's single linearised solve) */
};

typedef struct SolveCtx SolveCtx;
typedef struct OuterMethod OuterMethod;
typedef struct {
    const char *name;
    const char *description;
    unsigned flags; /* OUTER_* */
    /* Reads the options and allocates; sets base.ops and base.assembled. */
    int (*create)(SolverOptions *opt, OuterMethod **out);
    /* dv: in the initial guess, out the last accepted iterate. Returns
     * MPM_ENUMERIC on a numerical breakdown (the solver layer turns it into
     * status failed with the message as reason). */
    int (*solve)(OuterMethod *self, SolveCtx *ctx, double *dv, SolveStats *st);
    void (*view)(const OuterMethod *self, FILE *f);
    void (*destroy)(OuterMethod *self);
} OuterMethodOps;

struct OuterMethod {
    const OuterMethodOps *ops;
    /* sets its inverse approximation up from the assembled Hessian; 0 =
     * matrix-free (an inverse approximation with INV_NEEDS_HESSIAN is then
     * refused when the solver is created) */
    int assembled;
};

/* The operator of an assembled Hessian: its matrix and, for a distributed
 * run's halo, the problem (problem_assembled_product). */
typedef struct {
    StepProblem *pb;
    const Bsr *H;
} AssembledHessian;

struct SolveCtx {
    StepProblem *pb;
    InvApprox *inv;                /* never NULL */
    const LineSearchOps *ls;
    const StopRuleOps *stop;
    double stop_tol;               /* threshold of stop->measure */
    int stall_iters;               /* k of the stagnation rule */
    const SolveSettings *set;
    IterHook hook;
    void *hook_ctx;
    EventLog *log;                 /* where the wrappers time the phases (never NULL) */
    EventId phase[STEP_PHASES];    /* the step phases' events (core/step_phases.h) */
    /* kept by solve_should_stop */
    double best_energy, best_residual;
    double energy0; /* E at iteration 0 (the decrement rule's E_0) */
    int last_progress;
    AssembledHessian assembled; /* what solve_hessian_op's assembled operator reads */
};

/* The stopping test at the top of iteration `it` (g = gradient at the
 * current iterate, E its energy): records the CN residual in st, calls the
 * hook and returns 1 with st->status and st->reason set when the solve ends
 * here:
 *   failed    non-finite energy or residual;
 *   converged stop->measure < stop_tol;
 *   capped    it >= max_outer;
 *   timeout   set->deadline has passed;
 *   stalled   neither the energy nor the residual went below its best value
 *             for stall_iters iterations (an accepted equal energy counts as
 *             no decrease, so a stagnated solve cannot loop forever). */
int solve_should_stop(SolveCtx *c, const double *g, double E, int it, SolveStats *st);
/* The stopping rule's test on the iteration's search direction, after
 * the direction and before the line search: gTp = g^T p for the method's
 * own model minimiser p (before any fallback; NAN when p is none, e.g. a
 * CG that met negative curvature at once), E the current energy. Returns 1
 * with st->status converged when stop->direction_measure < stop_tol: the
 * solve then ends at the current iterate, without the step along p. */
int solve_direction_converged(SolveCtx *c, double gTp, double E, SolveStats *st);
/* 1 when the solve's time limit (set->deadline) has passed. */
int solve_past_deadline(const SolveCtx *c);
/* Calls the iteration hook (when set) with the time since the solve began
 * (the open "solve" event of the log);
 * for methods whose iterations do not go through solve_should_stop. */
void solve_report_iteration(SolveCtx *c, int it, double residual, double E);
/* E(dv), counted in ls_evals and timed in the linesearch phase. */
double solve_energy(SolveCtx *c, const double *dv, SolveStats *st);
/* g = grad E(dv) (the cache must hold dv: call after solve_energy at dv),
 * timed in the linesearch phase. */
void solve_gradient(SolveCtx *c, const double *dv, double *g, SolveStats *st);
/* Both at dv: returns E(dv), fills g. */
double solve_evaluate(SolveCtx *c, const double *dv, double *g, SolveStats *st);
/* The outer method's linear solves, their iterations counted in
 * linear_iters (the arguments are those of pcg_solve and minres_solve). */
int solve_pcg(SolveCtx *c, const LinearOp *op, const Projection *proj, const double *b, double *x,
              const PcgOptions *opt, PcgWork *work, PcgResult *res, SolveStats *st);
int solve_minres(SolveCtx *c, const LinearOp *op, const Projection *proj, const double *b, double *x,
                 const MinresOptions *opt, MinresWork *work, MinresResult *res, SolveStats *st);
/* Ends the solve with `status` and a printf-style reason; returns 1. */
int solve_end(SolveStats *st, SolveStatus status, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* The BC-projected Hessian as an operator: assembled H, or matrix-free
 * problem_hessvec when H is NULL. */
void solve_hessian_op(SolveCtx *c, const Bsr *H, LinearOp *op);
void solve_projection(SolveCtx *c, Projection *P);
/* Tangent stiffness at the cached iterate, then H (when not NULL) and the 9n
 * diagonal blocks (from H, or matrix-free); timed in the assemble phase.
 * solve_assemble uses the projected (SPD) tangent of SPEC 3, the one every
 * HOT-study solver sees; solve_assemble_unprojected the true dP/dF, which
 * may be indefinite (Gast et al. 2015's Newton, the semi-implicit method). */
int solve_assemble(SolveCtx *c, Bsr *H, double *diag, SolveStats *st);
int solve_assemble_unprojected(SolveCtx *c, Bsr *H, double *diag, SolveStats *st);
/* tau_g of Gast et al. 2015 §3.1's forcing term min(1/2, sigma sqrt(max(||g||,
 * tau_g))): the termination tolerance on ||g||, i.e. the stop rule's own
 * tolerance for "l2", and for the CN rule its L2 equivalent problem_tau(pb,
 * eps) (SPEC 4; the HOT code's newton.tolerance with --usecn). */
double solve_gradient_tolerance(const SolveCtx *c);
/* Sets the inverse approximation up at the current tangent, handing it the
 * solve's deadline; inv_setup times it in the setup phase. */
int solve_setup_inverse(SolveCtx *c, const Bsr *H, const double *diag, const LinearOp *op, const Projection *proj,
                        SolveStats *st);
/* The line-search strategy from dv along p, then the gradient at the
 * accepted point into g_new (unless the strategy gave it); everything timed
 * in the linesearch phase. When it stalls: st->status stalled with the strategy's
 * reason, the cache left at dv. */
int solve_line_search(SolveCtx *c, const double *dv, const double *g, const double *p, double E0, double gTp,
                      double *dv_new, double *g_new, LineSearchOutcome *out, SolveStats *st);
/* out = (I - P) dv + P free: dv's Dirichlet components with `free` on the
 * free subspace (P the BC projection); out may alias free but not dv, tmp (3n) is
 * scratch. For initial guesses and linearisation points other than dv. */
void solve_keep_dirichlet(const StepProblem *pb, const double *dv, const double *free_part, double *out, double *tmp);
/* solve_line_search along p from *dv, then, unless it stalled, the step:
 * dv = dv_new, *g and *g_new swapped (g holds the new gradient), *E the new
 * energy. Returns the line search's status; *stalled = 1 ends the solve
 * (st->status says why). */
int solve_take_step(SolveCtx *c, double *dv, double **g, double **g_new, const double *p, double *E, double gTp,
                    double *dv_new, SolveStats *st, int *stalled);
/* Hessian storage statistics of an assembled H (nothing when NULL). */
void solve_hessian_stats(const Bsr *H, SolveStats *st);
/* Grows vecs[k] to per_node[k] doubles per node for n nodes, k < count
 * (capacity in nodes kept in *cap, grown with headroom). */
int solve_reserve(double **const *vecs, const size_t *per_node, int count, int n, int *cap);

#endif
