/* The inverse-Hessian approximation interface (DESIGN "the one idea").
 *
 * Every solver is an outer method (projected Newton, L-BFGS, Gast15) combined
 * with an InvApprox: something that is set up from the step's BC-projected
 * Hessian (or, matrix-free, from its block diagonal and operator) and then
 * applied as z ~= H^-1 r. PN uses it as a PCG preconditioner, L-BFGS as the
 * initial inverse Hessian of the two-loop recursion. Same split as PETSc's
 * PC or SUNDIALS' SUNLinearSolver.
 *
 * An implementation embeds `InvApprox` as its first member and provides an
 * InvApproxOps table; adding one is a new file plus a registry line. */
#ifndef MPM_INVERSE_APPROX_H
#define MPM_INVERSE_APPROX_H

#include "core/bsr.h"
#include "core/node_order.h"
#include "solvers/linear_op.h"

struct StepProblem;

/* Free-form options (`--solver-opt key=value`), shared by all parts. Every
 * lookup records the key it asked for with the value in effect (given or
 * default), so that after a solver is created
 *  - a given key nobody asked for is reported as unknown (a typo must not
 *    run silently with the default; cf. PETSc's -options_left), and
 *  - the effective options can be written beside the results (run.json). */
#define SOLVER_MAX_OPTS 32
typedef struct {
    int n;
    char key[SOLVER_MAX_OPTS][32];
    char value[SOLVER_MAX_OPTS][64];
    int n_asked;                         /* distinct keys looked up */
    char asked[SOLVER_MAX_OPTS][32];
    char asked_value[SOLVER_MAX_OPTS][64]; /* value in effect */
} SolverOptions;

/* Looks up an option; returns the default when absent, and MPM_EINPUT through
 * *status (left untouched on success) when present but not a number. */
double solver_opt_number(SolverOptions *o, const char *key, double def, int *status);
const char *solver_opt_string(SolverOptions *o, const char *key, const char *def);
/* MPM_EINPUT naming the first option no lookup asked for, and the options
 * `who` does take. */
int solver_opts_check_used(const SolverOptions *o, const char *who);

typedef struct {
    int n_nodes;
    const Bsr *H;              /* BC-projected Hessian; NULL when matrix-free */
    const double *diag;        /* 9 n: diagonal blocks of the BC-projected Hessian (always given) */
    const int *coord;          /* 3 n: integer node coordinates, nodes sorted by node_order_key */
    const NodeColoring *coloring; /* block colouring of those nodes */
    const LinearOp *op;        /* the BC-projected Hessian as an operator */
    const Projection *proj;    /* Dirichlet projection of vectors */
    struct StepProblem *problem; /* for rediscretising methods (GMG) */
} InvSetupInput;

/* Work done by applications since the last setup (added to step statistics). */
typedef struct {
    long inner_iters;   /* PCG iterations inside (coarse solve, LBFGS-H) */
    double setup_s, apply_s;
} InvStats;

typedef struct InvApprox InvApprox;
typedef struct {
    const char *name;
    int (*create)(SolverOptions *opt, InvApprox **out);
    int (*setup)(InvApprox *self, const InvSetupInput *in);
    int (*apply)(InvApprox *self, const double *r, double *z);
    void (*destroy)(InvApprox *self);
} InvApproxOps;

struct InvApprox {
    const InvApproxOps *ops;
    InvStats stats;
    /* apply is not a fixed linear map (e.g. an adaptive inner PCG): PCG then
     * uses the flexible-CG beta (solvers/pcg.c) */
    int variable;
};

#endif
