#include "solvers/backtracking.h"

#include <math.h>

#include "core/error.h"

int linesearch_backtrack(StepProblem *pb, const double *dv, const double *p, double E0, double gTp,
                         const LineSearchOptions *opt, double *dv_new, LineSearchResult *res)
{
    size_t len = 3 * (size_t)pb->n_nodes;
    double alpha = 1.0;
    res->evals = 0;
    res->stalled = 0;
    for (int h = 0; h <= opt->max_halvings; ++h, alpha *= 0.5) {
#pragma omp parallel for schedule(static)
        for (size_t k = 0; k < len; ++k) dv_new[k] = dv[k] + alpha * p[k];
        double E = problem_energy(pb, dv_new);
        res->evals++;
        double bound = opt->armijo ? E0 + 1e-4 * alpha * gTp : E0;
        if (isfinite(E) && E <= bound) {
            res->alpha = alpha;
            res->energy = E;
            return MPM_OK;
        }
    }
    /* leave the cache at dv so the caller's state stays consistent */
    res->energy = problem_energy(pb, dv);
    res->evals++;
    res->alpha = 0.0;
    res->stalled = 1;
    return MPM_OK;
}
