/* Line-search strategies an outer method is handed (docs/design.md, "the one idea";
 * SPEC 5): chosen by the solver option `linesearch=NAME`, never a code path
 * inside a method: "halving" (the reference rule, SPEC 5), "armijo" and
 * "wolfe" (strong Wolfe conditions, Nocedal & Wright Alg. 3.5/3.6, as Gast
 * et al. 2015 §3.1 use; alpha may exceed 1). Adding one is one function with
 * this signature, a LineSearchOps and one line in the table of
 * line_search.c.
 *
 * Contract of search(): from dv along the descent direction p (gTp = g(dv).p
 * < 0, E0 = E(dv), g0 = g(dv)) find dv_new = dv + alpha p with an acceptable
 * energy. On success (stalled == 0) the problem's cache holds dv_new and, when
 * the strategy evaluated it anyway, g_new = g(dv_new) with have_gradient = 1
 * (else the caller evaluates it). With no acceptable alpha it sets stalled,
 * leaves the cache at dv and says why in `why`. It never accepts an energy
 * above E0 (tests/conformance/test_conformance.c). */
#ifndef MPM_LINE_SEARCH_H
#define MPM_LINE_SEARCH_H

#include "core/problem.h"

typedef struct {
    int max_halvings; /* 60 (SPEC 5) */
} LineSearchParams;

typedef struct {
    double alpha;
    double energy;     /* E(dv_new) */
    int evals;         /* energy evaluations */
    int have_gradient; /* g_new = g(dv_new) filled */
    int conditions_met; /* wolfe: both strong Wolfe conditions hold at alpha (0 when
                           the evaluation budget ran out and the best point with
                           sufficient decrease was taken); the others: 1 */
    int stalled;
    char why[96];      /* when stalled */
} LineSearchOutcome;

typedef struct {
    const char *name;
    const char *description;
    int (*search)(StepProblem *pb, const double *dv, const double *p, double E0, const double *g0, double gTp,
                  const LineSearchParams *prm, double *dv_new, double *g_new, LineSearchOutcome *out);
} LineSearchOps;

int line_search_count(void);
const LineSearchOps *line_search_get(int i);
/* NULL when unknown. */
const LineSearchOps *line_search_find(const char *name);

/* Strong Wolfe constants (Nocedal & Wright §3.1: c1 = 1e-4, c2 = 0.9 for
 * Newton-type directions) and the largest step the expansion tries. */
#define WOLFE_C1 1e-4
#define WOLFE_C2 0.9
#define WOLFE_ALPHA_MAX 1e6

#endif
