/* The inverse-Hessian approximation interface (docs/design.md, "the one idea").
 *
 * Every solver is an outer method (solvers/outer_method.h) combined with an
 * InvApprox: something that is set up from the step's BC-projected Hessian
 * (or, matrix-free, from its block diagonal and operator) and then applied as
 * z ~= H^-1 r. Projected Newton uses it as a PCG preconditioner, L-BFGS as
 * the initial inverse Hessian of the two-loop recursion. Same split as
 * PETSc's PC or SUNDIALS' SUNLinearSolver.
 *
 * An implementation embeds `InvApprox` as its first member, sets `caps` in
 * create and provides an InvApproxOps table; adding one is a new file plus
 * one line in experiments/driver/registry.c. Nothing outside the implementation's
 * file knows its type: its statistics come through the view op. Callers go
 * through the inv_* wrappers below, which keep the object's state (apply
 * before a successful setup is refused) and count inner iterations across
 * setups. tests/conformance/test_conformance.c checks every registered implementation
 * against this contract. */
#ifndef MPM_INVERSE_APPROX_H
#define MPM_INVERSE_APPROX_H

#include <stdint.h>
#include <stdio.h>

#include "core/bsr.h"
#include "core/deadline.h"
#include "core/dist/comm_ops.h"
#include "core/dist/decomposition.h"
#include "core/event_log.h"
#include "core/node_order.h"
#include "solvers/krylov/linear_op.h"
#include "solvers/solver_options.h"

struct StepProblem;

typedef struct {
    int n_nodes;
    const Bsr *H;              /* BC-projected Hessian; NULL when matrix-free */
    const double *diag;        /* 9 n: diagonal blocks of the BC-projected Hessian (always given) */
    const int *coord;          /* 3 n: integer node coordinates, nodes sorted by node_order_key */
    const NodeColoring *coloring; /* block colouring of those nodes */
    const LinearOp *op;        /* the BC-projected Hessian as an operator */
    const Projection *proj;    /* Dirichlet projection of vectors */
    struct StepProblem *problem; /* for rediscretising methods (GMG) */
    /* the solve's deadline (--max-step-seconds / --max-run-seconds): past
     * it no inner iteration starts, an inner solve stops with its current
     * iterate */
    Deadline deadline;
    /* A problem over MPI ranks (docs/distributed.md; NULL: one process):
     * the nodes are the rank's local ones, owned[i] = 1 where it owns node
     * i; vectors hold zeros at ghosts; H is the rank's part (ghost rows
     * partial: problem_assemble), diag and op are the whole scene's. Only
     * an INV_DISTRIBUTED implementation is set up with comm. */
    const CommOps *comm;
    const unsigned char *owned;
    const Decomposition *decomp; /* the owner of any grid position (coarse levels' nodes) */
} InvSetupInput;

/* Capability flags (InvApprox.caps, set by create from the options). */
enum {
    INV_NEEDS_HESSIAN = 1u << 0,  /* setup reads InvSetupInput.H: refused when it is NULL */
    INV_MATRIX_FREE = 1u << 1,   /* works from diag, op and proj alone (H may be NULL) */
    INV_NEEDS_PROBLEM = 1u << 2, /* setup reads InvSetupInput.problem (rediscretisation) */
    INV_VARIABLE = 1u << 3,      /* apply is not a fixed linear map (an adaptive inner solve) */
    INV_SYMMETRIC = 1u << 4,     /* apply is a symmetric map: x^T M y = y^T M x */
    INV_POSITIVE = 1u << 5,      /* r^T M r > 0 for r != 0 in the free subspace (H SPD) */
    INV_INNER_ITERS = 1u << 6,   /* apply iterates inside (counts InvStats.inner_iters) */
    INV_DISTRIBUTED = 1u << 7,   /* set up and applied on a rank's part of a problem over ranks (InvSetupInput.comm) */
};

/* Work done since the last setup. The seconds are the wrappers' intervals
 * in InvApprox.log (0 when it is NULL): setup_s of the last setup request,
 * apply_s of the applies since. */
typedef struct {
    long inner_iters;   /* iterations inside (coarse PCG, LBFGS-H's PCG) */
    double setup_s, apply_s;
} InvStats;

/* What view returns: the hierarchy of the last setup (multigrid: nodes and
 * blocks per row per level; written as mg_levels.csv) and named statistics
 * (AMG levels and operator complexity, factor nonzeros, ...). */
#define INV_VIEW_MAX_LEVELS 16
#define INV_VIEW_MAX_STATS 16
#define INV_VIEW_TEXT 16384
typedef struct {
    int nodes;
    int64_t blocks;
    double blocks_per_row_avg;
    int blocks_per_row_max;
} InvLevelView;
typedef struct {
    int n_levels; /* 0: no level table */
    InvLevelView level[INV_VIEW_MAX_LEVELS];
    int n_stats;
    struct {
        char key[32];
        double value;
    } stat[INV_VIEW_MAX_STATS];
    /* the library's own description of the last setup, the effective
     * options it ran with (PETSc's KSPView), for run.json; "" = none */
    char library_view[INV_VIEW_TEXT];
} InvView;
/* Appends a named statistic (ignored once the table is full). */
void inv_view_add(InvView *v, const char *key, double value);

typedef struct InvApprox InvApprox;
typedef struct {
    const char *name;
    const char *description;
    /* Reads the options (each through solver_opt_*, so unknown ones are
     * caught), allocates the object and sets base.ops and base.caps. Needs
     * no step problem: creating validates the options. */
    int (*create)(SolverOptions *opt, InvApprox **out);
    int (*setup)(InvApprox *self, const InvSetupInput *in);
    int (*apply)(InvApprox *self, const double *r, double *z);
    /* Prints a summary of the last setup to f (when not NULL) and fills out
     * (when not NULL; zeroed by the caller). */
    void (*view)(const InvApprox *self, FILE *f, InvView *out);
    void (*destroy)(InvApprox *self);
    /* One-time start-up of the library behind the implementation (MPI and
     * hypre, CHOLMOD), run by the run layer before the first step so that no
     * step is charged with it (startup_s); NULL: nothing to start. */
    int (*library_startup)(void);
    /* Optional: take `in`, whose nodes and sparsity pattern are those of the
     * last full setup, without setting up again (setup reuse, docs/solvers.md
     * "Setup reuse"; the wrapper decides when). values = 1: the matrix values
     * changed; update what depends on them on the kept structure (CHOLMOD:
     * numeric refactorisation on the kept symbolic analysis; mg: the Galerkin
     * products on the kept transfers) and set *refreshed = 1, or keep the old
     * numbers (a lagged inverse) and set *refreshed = 0. values = 0: keep the
     * numbers, only take in's arrays (pointers into the step may move).
     * Either way the result must keep the caps (symmetric, positive).
     * NULL: the implementation is set up afresh at every request. */
    int (*reuse)(InvApprox *self, const InvSetupInput *in, int values, int *refreshed);
    /* The version of the library behind the implementation (run.json's
     * provenance); NULL: in-house, no library. */
    const char *(*library_version)(void);
} InvApproxOps;

/* Setup reuse counters (since creation): every inv_setup call is one
 * request and exactly one of rebuilds, refreshes, lagged. */
typedef struct {
    long requests;
    long rebuilds;       /* full setups */
    long refreshes;      /* reuse op with new values applied */
    long lagged;         /* kept as it was (values not updated) */
    long pattern_misses; /* a reuse the options allowed, dropped because the nodes or pattern changed */
} InvReuseStats;

struct InvApprox {
    const InvApproxOps *ops;
    unsigned caps;      /* INV_* */
    InvStats stats;
    /* outer PCG uses the flexible-CG beta (solvers/krylov/pcg.c); usually
     * caps & INV_VARIABLE, an option may turn it off (mg flexible=0) */
    int flexible;
    /* threads the library behind setup and apply runs on (hypre: 1 in
     * Debian's build); 0 = the run's OpenMP threads. Set by create. */
    int setup_threads, apply_threads;
    /* where the wrappers time setup (the step phase "setup") and apply
     * (the event "inverse_apply", a sub-phase of "solve"), and an
     * implementation its own sub-phases: &own_log, set by inv_create,
     * unless its user hands another (solver_solve: the solve's log, for the
     * solve); NULL: nothing is timed */
    EventLog *log;
    EventLog own_log;
    EventId setup_event, apply_event; /* registered by inv_create */
    /* kept by the wrappers */
    int ready;          /* the last setup succeeded */
    long inner_banked;  /* inner iterations of setups before the current one */
    /* setup reuse: options reuse_every (K; 0 = while the key holds),
     * reuse_across_steps, reuse_refresh, read by inv_create */
    int reuse_every, reuse_across_steps, reuse_refresh;
    int solve_requests;   /* requests since inv_begin_solve */
    long since_rebuild;   /* requests since the last full setup */
    int have_key;         /* key of the last full setup is valid */
    uint64_t key;         /* hash of the nodes (coordinates) and the pattern id */
    InvReuseStats reuse;
};

/* The wrappers' events (registered on the first call): the step phase
 * "setup" (core/step_phases.h) and "inverse_apply", under which an
 * implementation registers its own sub-phases. */
int inv_events(EventId *setup, EventId *apply);

/* The way to use an InvApprox. inv_setup marks it ready on success (not
 * ready on failure); inv_apply refuses (MPM_EINTERNAL) when not ready. */
int inv_create(const InvApproxOps *ops, SolverOptions *opt, InvApprox **out);
/* inv_setup is a setup request: a full setup, or, as the reuse options
 * allow and the implementation's reuse op supports, a refresh or a lagged
 * reuse of the last one. A full setup happens at the first request of a
 * solve (unless reuse_across_steps), when the node coordinates or the
 * matrix pattern differ from the last full setup's, and once reuse_every
 * requests have passed since it. */
int inv_setup(InvApprox *M, const InvSetupInput *in);
/* Marks the start of a solve (one time step): the next request is its first. */
void inv_begin_solve(InvApprox *M);
int inv_apply(InvApprox *M, const double *r, double *z);
void inv_view(const InvApprox *M, FILE *f, InvView *out);
void inv_destroy(InvApprox *M);
/* Inner iterations since creation (across setups). */
long inv_inner_iters(const InvApprox *M);
/* "needs the assembled Hessian, variable, ..." for listings. */
void inv_caps_describe(unsigned caps, char *buf, size_t len);

#endif
