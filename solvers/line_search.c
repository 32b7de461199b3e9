/* The line-search strategies (see line_search.h). Both backtracking rules
 * are solvers/backtracking.c's (SPEC 5: alpha = 1, halve until accepted, at most
 * max_halvings halvings); the strong Wolfe search is below. */
#include "solvers/line_search.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "solvers/backtracking.h"
#include "core/vec.h"

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
    out->conditions_met = !lr.stalled;
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

/* ---- strong Wolfe (Nocedal & Wright, Numerical Optimization, 2nd ed.,
 * Alg. 3.5 and 3.6; Gast et al. 2015 §3.1) ----
 * phi(alpha) = E(dv + alpha p), phi'(alpha) = g(dv + alpha p).p. A step is
 * accepted when
 *   phi(alpha) <= phi(0) + c1 alpha phi'(0)     (sufficient decrease)
 *   |phi'(alpha)| <= c2 |phi'(0)|               (strong curvature)
 * Alg. 3.5 tries alpha = 1 first (so a good Newton step costs one energy and
 * one gradient, which the outer method needs anyway), doubles alpha while
 * the energy keeps falling steeply (alpha may exceed 1, up to
 * WOLFE_ALPHA_MAX), and hands a bracket to zoom (Alg. 3.6), which picks the
 * next trial by the minimiser of the cubic through phi and phi' at the two
 * ends (N&W eq. 3.59), or by bisection when that minimiser does not exist or
 * lies within 10 % of the bracket's width from an end. Every trial evaluates
 * the energy and the gradient; the budget is max_halvings + 1 trials. */

typedef struct {
    double a, f, d; /* alpha, phi(alpha), phi'(alpha) */
} WolfePoint;

typedef struct {
    StepProblem *pb;
    const double *dv, *p;
    double *dv_new, *g_new;
    size_t len;
    double f0, d0;
    int evals, budget;
} WolfeSearch;

/* Evaluates phi and phi' at alpha (the cache then holds dv + alpha p). */
static WolfePoint wolfe_eval(WolfeSearch *w, double alpha)
{
    const size_t len = w->len;
    const double *dv = w->dv, *p = w->p;
    double *x = w->dv_new;
#pragma omp parallel for schedule(static)
    for (size_t k = 0; k < len; ++k) x[k] = dv[k] + alpha * p[k];
    WolfePoint q = {alpha, problem_energy(w->pb, x), NAN};
    w->evals++;
    if (isfinite(q.f)) {
        problem_gradient(w->pb, x, w->g_new);
        q.d = vec_dot(len, w->g_new, p);
    }
    return q;
}

static int wolfe_sufficient(const WolfeSearch *w, const WolfePoint *q)
{
    return isfinite(q->f) && q->f <= w->f0 + WOLFE_C1 * q->a * w->d0;
}

static int wolfe_curvature(const WolfeSearch *w, const WolfePoint *q)
{
    return isfinite(q->d) && fabs(q->d) <= -WOLFE_C2 * w->d0;
}

/* The next trial inside the bracket (lo, hi): the cubic interpolant's
 * minimiser when it is well inside, else the midpoint. */
static double wolfe_interpolate(const WolfePoint *lo, const WolfePoint *hi)
{
    double mid = 0.5 * (lo->a + hi->a);
    if (!isfinite(hi->f) || !isfinite(hi->d) || !isfinite(lo->d)) return mid;
    /* N&W eq. (3.59) with alpha_{i-1} = lo, alpha_i = hi */
    double d1 = lo->d + hi->d - 3.0 * (lo->f - hi->f) / (lo->a - hi->a);
    double disc = d1 * d1 - lo->d * hi->d;
    if (!(disc >= 0.0)) return mid;
    double d2 = copysign(sqrt(disc), hi->a - lo->a);
    double den = hi->d - lo->d + 2.0 * d2;
    if (den == 0.0) return mid;
    double a = hi->a - (hi->a - lo->a) * (hi->d + d2 - d1) / den;
    double left = fmin(lo->a, hi->a), width = fabs(hi->a - lo->a);
    if (!isfinite(a) || a < left + 0.1 * width || a > left + 0.9 * width) return mid;
    return a;
}

/* Alg. 3.6: lo satisfies sufficient decrease with the lowest phi seen, and
 * phi'(lo) (hi - lo) < 0. Returns 1 with *acc the accepted point (the last
 * evaluated), 0 when the budget ran out (*acc = lo). */
static int wolfe_zoom(WolfeSearch *w, WolfePoint lo, WolfePoint hi, WolfePoint *acc)
{
    while (w->evals < w->budget && fabs(hi.a - lo.a) > 1e-15 * fmax(lo.a, hi.a)) {
        WolfePoint q = wolfe_eval(w, wolfe_interpolate(&lo, &hi));
        if (!wolfe_sufficient(w, &q) || q.f >= lo.f) {
            hi = q;
        } else {
            if (wolfe_curvature(w, &q)) {
                *acc = q;
                return 1;
            }
            if (q.d * (hi.a - lo.a) >= 0.0) hi = lo;
            lo = q;
        }
    }
    *acc = lo;
    return 0;
}

static int strong_wolfe(StepProblem *pb, const double *dv, const double *p, double E0, const double *g0, double gTp,
                        const LineSearchParams *prm, double *dv_new, double *g_new, LineSearchOutcome *out)
{
    (void)g0;
    memset(out, 0, sizeof *out);
    WolfeSearch w = {pb, dv, p, dv_new, g_new, 3 * (size_t)pb->n_nodes, E0, gTp, 0, prm->max_halvings + 1};
    WolfePoint prev = {0.0, E0, gTp}, acc = prev;
    int found = 0, last_is_acc = 0;
    double alpha = 1.0;
    /* Alg. 3.5 */
    for (int i = 1; w.evals < w.budget; ++i) {
        WolfePoint q = wolfe_eval(&w, alpha);
        if (!wolfe_sufficient(&w, &q) || (i > 1 && q.f >= prev.f)) {
            found = wolfe_zoom(&w, prev, q, &acc);
            last_is_acc = found;
            break;
        }
        if (wolfe_curvature(&w, &q)) {
            acc = q;
            found = last_is_acc = 1;
            break;
        }
        if (q.d >= 0.0) {
            found = wolfe_zoom(&w, q, prev, &acc);
            last_is_acc = found;
            break;
        }
        acc = prev = q; /* sufficient decrease, still steeply downhill: expand */
        last_is_acc = 1;
        if (alpha >= WOLFE_ALPHA_MAX) break;
        alpha = fmin(2.0 * alpha, WOLFE_ALPHA_MAX);
    }
    out->evals = w.evals;
    out->conditions_met = found;
    if (acc.a > 0.0) {
        /* the accepted point; when the budget ran out, the best point with
         * sufficient decrease (energy below E0), re-evaluated unless it was
         * the last trial so the cache and g_new belong to it */
        if (!last_is_acc) {
            WolfePoint q = wolfe_eval(&w, acc.a);
            out->evals = w.evals;
            acc = q;
        }
        out->alpha = acc.a;
        out->energy = acc.f;
        out->have_gradient = 1;
        return MPM_OK;
    }
    out->energy = problem_energy(pb, dv); /* leave the cache at dv */
    out->evals = ++w.evals;
    out->alpha = 0.0;
    out->stalled = 1;
    snprintf(out->why, sizeof out->why, "line search: no sufficient decrease (strong Wolfe) in %d trials", w.budget);
    return MPM_OK;
}

static const LineSearchOps g_halving = {"halving", "backtracking by halves until the energy does not increase",
                                        halving};
static const LineSearchOps g_armijo = {"armijo", "backtracking by halves until Armijo's condition (c = 1e-4) holds",
                                       armijo};
static const LineSearchOps g_wolfe = {
    "wolfe", "strong Wolfe conditions (c1 = 1e-4, c2 = 0.9; Nocedal & Wright Alg. 3.5/3.6), alpha may exceed 1",
    strong_wolfe};
static const LineSearchOps *const g_line_searches[] = {&g_halving, &g_armijo, &g_wolfe};

int line_search_count(void) { return (int)(sizeof g_line_searches / sizeof g_line_searches[0]); }

const LineSearchOps *line_search_get(int i) { return i >= 0 && i < line_search_count() ? g_line_searches[i] : NULL; }

const LineSearchOps *line_search_find(const char *name)
{
    for (int i = 0; i < line_search_count(); ++i)
        if (strcmp(g_line_searches[i]->name, name) == 0) return g_line_searches[i];
    return NULL;
}
