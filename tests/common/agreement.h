/* floor: driver */
/* Solver agreement on the first step problem of a scene (SPEC 4, 5, 7, 11),
 * shared by tests/conformance/test_solvers.c (APIC, twist) and
 * test_solvers_mls.c (MLS, stretched-box and bar3); the checks and their
 * bounds are described in test_solvers.c. */
#ifndef MPM_TEST_AGREEMENT_H
#define MPM_TEST_AGREEMENT_H

#include "core/step.h"
#include "solvers/outer_method.h"

typedef struct {
    const char *scene;
    double scale;
    TransferKind transfer;
    const char *reference; /* the reference dv*'s solver, at eps_ref */
    double eps_ref;
    double eps;            /* every preset's tolerance */
    int min_outer;         /* the first preset needs at least this many outer iterations (a hard step) */
} AgreementCase;

typedef struct {
    double *dv;
    SolveStats st;
    int monotone;
    int skipped; /* not judged here */
} AgreementOutcome;

/* Solves c's first step with `spec` at eps (a preset with its own stopping
 * rule is judged by the CN rule); MPM_OK or the failing status. out->dv is
 * the caller's to free. */
int agreement_solve_first_step(const AgreementCase *c, const char *spec, double eps, AgreementOutcome *out);

/* Every preset that iterates to a tolerance converges at c->eps, never raises
 * the energy, reports the CN residual of the dv it returns and lies within
 * the two-sided a-posteriori bound of the reference (CHECKs). */
void agreement_check(const AgreementCase *c);

#endif
