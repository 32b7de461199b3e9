/* The line-search strategies (see line_search.h). Both backtracking rules
 * are core/linesearch.c's (SPEC 5: alpha = 1, halve until accepted, at most
 * max_halvings halvings). */
#include "solvers/line_search.h"

#include <stdio.h>
#include <string.h>

#include "core/linesearch.h"

static int backtrack(int armijo, StepProblem *pb, const double *dv, const double *p, double E0, double gTp,
                     const LineSearchParams *prm, double *dv_new, LineSearchOutcome *out)
{
    LineSearchOptions lso = {armijo, prm->max_halvings};
    LineSearchResult lr;
    int st = linesearch_backtrack(pb, dv, p, E0, gTp, &lso, dv_new, &lr);
    memset(out, 0, sizeof *out);
    out->alpha = lr.alpha;
    out->energy = lr.energy;
    out->evals = lr.evals;
    out->stalled = lr.stalled;
    if (lr.stalled)
        snprintf(out->why, sizeof out->why, "line search: no %s in %d halvings",
                 armijo ? "sufficient decrease (Armijo)" : "energy decrease", prm->max_halvings);
    return st;
}

/* E(dv + alpha p) <= E(dv): the reference rule */
static int halving(StepProblem *pb, const double *dv, const double *p, double E0, const double *g0, double gTp,
                   const LineSearchParams *prm, double *dv_new, double *g_new, LineSearchOutcome *out)
{
    (void)g0;
    (void)g_new;
    return backtrack(0, pb, dv, p, E0, gTp, prm, dv_new, out);
}

/* E(dv + alpha p) <= E(dv) + 1e-4 alpha g.p */
static int armijo(StepProblem *pb, const double *dv, const double *p, double E0, const double *g0, double gTp,
                  const LineSearchParams *prm, double *dv_new, double *g_new, LineSearchOutcome *out)
{
    (void)g0;
    (void)g_new;
    return backtrack(1, pb, dv, p, E0, gTp, prm, dv_new, out);
}

static const LineSearchOps g_halving = {"halving", "backtracking by halves until the energy does not increase",
                                        halving};
static const LineSearchOps g_armijo = {"armijo", "backtracking by halves until Armijo's condition (c = 1e-4) holds",
                                       armijo};
static const LineSearchOps *const g_line_searches[] = {&g_halving, &g_armijo};

int line_search_count(void) { return (int)(sizeof g_line_searches / sizeof g_line_searches[0]); }

const LineSearchOps *line_search_get(int i) { return i >= 0 && i < line_search_count() ? g_line_searches[i] : NULL; }

const LineSearchOps *line_search_find(const char *name)
{
    for (int i = 0; i < line_search_count(); ++i)
        if (strcmp(g_line_searches[i]->name, name) == 0) return g_line_searches[i];
    return NULL;
}
