/* Backtracking line search shared by every outer method (SPEC 5; HOT
 * reference §6.4): alpha = 1, halve until E(dv + alpha p) <= E(dv) (or the
 * Armijo condition with c = 1e-4 when asked), at most max_halvings halvings.
 * Unlike the reference, the number of halvings is capped so the step reports
 * "stalled" instead of looping until alpha underflows. */
#ifndef MPM_LINESEARCH_H
#define MPM_LINESEARCH_H

#include "core/problem.h"

typedef struct {
    int armijo;        /* 0: simple decrease (reference), 1: Armijo c = 1e-4 */
    int max_halvings;  /* 60 */
} LineSearchOptions;

typedef struct {
    double alpha;
    double energy;     /* E at the accepted point */
    int evals;         /* energy evaluations */
    int stalled;       /* no acceptable alpha within max_halvings */
} LineSearchResult;

/* Tries dv_new = dv + alpha p. On success the problem's cache holds the
 * accepted point. gTp = g(dv).p (used by Armijo). dv_new must not alias dv. */
int linesearch_backtrack(StepProblem *pb, const double *dv, const double *p, double E0, double gTp,
                         const LineSearchOptions *opt, double *dv_new, LineSearchResult *res);

#endif
