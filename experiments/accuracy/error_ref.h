/* Per-step solver error (SPEC 11; `run --error-ref SPEC`): after each step's
 * solve, before step_end, the same step problem (same dv0, Dirichlet nodes,
 * F^n) is solved again from the same initial guess by a reference solver at
 * a tight tolerance, and the solver's dv is compared with the reference's
 * dv*:
 *
 *   err_h     = ||dv - dv*||_H / ||dv* - dv0||_H, H = the BC-projected
 *               Hessian at dv* with the projected (SPD) tangent, the matrix
 *               every solver sees (P H P + I - P, core/problem.h);
 *   e_gap     = (E(dv) - E(dv*)) / |E(dv0) - E(dv*)|;
 *   err_v_max = max over nodes |dv_i - dv*_i| dt / dx, the velocity error as
 *               the fraction of a cell a particle moves wrongly in a step.
 *
 * SPEC is SOLVER[:eps] with SOLVER a solver spec (registry.h) or "auto" and
 * eps the reference's CN tolerance (default 1e-12). "auto" takes pn-cholmod
 * (exact Newton) at the steps whose factor fits the memory budget and
 * pn-pcg at the others (error_ref_cholmod_fits), and at a step whose
 * CHOLMOD factorisation breaks down (one line on stderr says so), each step
 * saying which in steps.csv's ref_solver (a build without CHOLMOD takes
 * pn-pcg at every step). Against a reference that failed
 * the metrics are empty (ref_status failed). The reference solve and the metrics run inside
 * time_step_run's after-solve hook, whose time goes to no timing column (it is
 * ref_s); the problem's iterate cache is left at dv afterwards. */
#ifndef MPM_ERROR_REF_H
#define MPM_ERROR_REF_H

#include <stddef.h>

#include "core/problem.h"
#include "solvers/solver.h"

#define ERROR_REF_DEFAULT_EPS 1e-12

/* Memory budget of the "auto" choice: this fraction of the physical memory. */
#define ERROR_REF_MEMORY_FRACTION 0.25

typedef struct {
    int valid;              /* the metrics below are set (the reference ran) */
    double err_h, e_gap, err_v_max; /* NAN when undefined (0 / 0, non-finite dv) */
    double ref_s;           /* the reference solve and the metrics */
    SolveStatus ref_status;
    double ref_residual;
    const char *ref_solver; /* the reference's spec */
} StepError;

typedef struct ErrorRef ErrorRef;

/* Splits SPEC into the solver spec and eps (MPM_EINPUT, one line, for a
 * malformed spec; the solver itself is checked by error_ref_check). */
int error_ref_parse(const char *spec, char *solver, size_t n, double *eps);
/* Validates SPEC completely (the reference solvers with solver_spec_check,
 * eps in range) without a step problem. */
int error_ref_check(const char *spec);
int error_ref_create(const char *spec, ErrorRef **out);
/* Starts the libraries the reference solvers use (library_startup.h). */
int error_ref_startup(const ErrorRef *r);
/* The reference's description for run.json and the run's header. */
const char *error_ref_describe(const ErrorRef *r);

/* Estimated bytes of the CHOLMOD factor of an n-node step Hessian: nested
 * dissection on a 3D grid fills nnz(L) ~ C N^(4/3) for N = 3 n unknowns; C =
 * 40 bounds what bar3, twist and wheel gave at 1.6k-4.9k nodes (22-29),
 * 12 bytes per nonzero (value, row index, supernodal slack). */
double error_ref_cholmod_bytes(int n_nodes);
/* Whether that estimate is within ERROR_REF_MEMORY_FRACTION of the memory. */
int error_ref_cholmod_fits(int n_nodes);

/* time_step_run's after-solve hook (ctx = ErrorRef *): the reference solve of pb
 * and the metrics for the solver's dv. Errors other than a numerical
 * breakdown of the reference (which is its ref_status) are returned. */
int error_ref_measure(void *ctx, StepProblem *pb, const double *dv);
/* The last step's result; cleared (valid 0) by error_ref_clear. */
const StepError *error_ref_last(const ErrorRef *r);
void error_ref_clear(ErrorRef *r);
void error_ref_destroy(ErrorRef *r);

#endif
