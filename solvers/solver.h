/* A named solver = an outer method x an inverse-Hessian approximation x
 * options (DESIGN "the one idea"). The registry of presets lives in
 * experiments/registry.c; this file is the run-time object. */
#ifndef MPM_SOLVER_H
#define MPM_SOLVER_H

#include <stdint.h>

#include "core/bsr.h"
#include "core/problem.h"
#include "solvers/inverse_approx.h"
#include "solvers/pcg.h"

typedef enum { METHOD_PN = 0, METHOD_LBFGS = 1, METHOD_GAST15 = 2 } OuterMethod;

typedef enum { SOLVE_CONVERGED = 0, SOLVE_CAPPED, SOLVE_STALLED, SOLVE_FAILED } SolveStatus;
const char *solve_status_name(SolveStatus s);

typedef struct {
    const char *name;
    const char *description;
    OuterMethod method;
    const InvApproxOps *inv;  /* PCG preconditioner (PN) or initial inverse Hessian (L-BFGS) */
    int matrix_free;          /* PN: Hessian only as products, preconditioner from the diagonal */
    const char *defaults;     /* "key=value,key=value" preset options (overridable) */
} SolverPreset;

typedef struct {
    double eps;           /* CN tolerance (SPEC 4), default 1e-7 */
    int max_outer;        /* 10000 */
    int max_linear;       /* 10000 */
    int armijo;           /* line-search rule (SPEC 5) */
    int max_halvings;     /* 60 */
} SolveSettings;

typedef struct {
    int outer_iters;
    long linear_iters;
    int ls_evals;
    double residual;      /* scaled CN residual at the returned dv */
    SolveStatus status;
    double assemble_s, setup_s, solve_s, linesearch_s;
    int64_t hessian_blocks;
    size_t hessian_bytes;
} SolveStats;

/* Called at every outer iteration with the CN residual and energy. */
typedef void (*IterHook)(void *ctx, int iter, double elapsed_s, double residual, double energy);

typedef struct Solver {
    const SolverPreset *preset;
    SolverOptions opts;
    InvApprox *inv;
    Bsr H;
    PcgWork pcg;
    int cap_nodes;
    double *g, *p, *dv_new, *g_new, *diag; /* 3n / 9n work vectors */
    /* L-BFGS history */
    int window;
    double *S, *Y, *rho_hist, *xi;        /* window x 3n, window */
} Solver;

void solve_settings_default(SolveSettings *s);
int solver_create(const SolverPreset *preset, const SolverOptions *opts, Solver **out);
/* Minimises the step problem from dv (in: initial guess, out: solution). */
int solver_solve(Solver *s, StepProblem *pb, const SolveSettings *set, double *dv, SolveStats *st,
                 IterHook hook, void *hook_ctx);
void solver_destroy(Solver *s);

/* Outer methods (one file each). */
int pn_solve(Solver *s, StepProblem *pb, const SolveSettings *set, double *dv, SolveStats *st, IterHook hook,
             void *hook_ctx);

int lbfgs_solve(Solver *s, StepProblem *pb, const SolveSettings *set, double *dv, SolveStats *st, IterHook hook,
                void *hook_ctx);

/* The stopping test every outer method runs at the top of iteration `it`
 * (SPEC 4, 5): records the CN residual of g in st and calls the hook; returns
 * 1 with st->status set when the solve ends here (converged, failed on a
 * non-finite residual or energy, or capped at max_outer), 0 to iterate. */
int solver_should_stop(StepProblem *pb, const SolveSettings *set, const double *g, double E, int it, double t_start,
                       IterHook hook, void *hook_ctx, SolveStats *st);
/* Shared by the outer methods: grows work vectors to n nodes. */
int solver_reserve(Solver *s, int n_nodes);
/* The BC-projected Hessian as a LinearOp (assembled or matrix-free). */
void solver_hessian_op(Solver *s, StepProblem *pb, int assembled, LinearOp *op);
/* Projection onto free dofs as a Projection. */
void solver_projection(StepProblem *pb, Projection *P);
/* Sets up the inverse approximation at the current tangent; fills diag. */
int solver_setup_inverse(Solver *s, StepProblem *pb, int assembled, LinearOp *op, Projection *proj);

#endif
