/* floor: solvers */
/* The shared backtracking line search (SPEC 5, solvers/backtracking.c) on a real
 * step problem (tests/common/fixture.c), along a steepest-descent direction long
 * enough that alpha = 1 overshoots:
 *  - simple decrease (the reference rule): the accepted alpha is the first
 *    power of 1/2 with E <= E0, and the trial before it was rejected;
 *  - Armijo (c = 1e-4): the accepted point satisfies E <= E0 + c alpha g.p
 *    and alpha is never larger than the simple rule's;
 *  - the problem's cache holds the accepted point (the gradient from the
 *    cache equals a freshly evaluated one);
 *  - an ascent direction stalls after max_halvings halvings, reports
 *    stalled, and leaves the cache at the starting point. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "solvers/backtracking.h"
#include "core/vec.h"
#include "tests/common/fixture.h"
#include "tests/common/testutil.h"

static double *alloc3(int n) { return calloc(3 * (size_t)n, sizeof(double)); }

int main(void)
{
    FixtureOptions o;
    fixture_default(&o);
    o.two_materials = 1;
    o.gravity[1] = -9.8;
    Fixture f;
    CHECK(fixture_build(&f, &o) == 0, "fixture");
    StepProblem *pb = &f.pb;
    const int n = pb->n_nodes;
    const size_t len = 3 * (size_t)n;
    double *dv = alloc3(n), *g = alloc3(n), *p = alloc3(n), *dv_new = alloc3(n), *g_cache = alloc3(n),
           *g_fresh = alloc3(n), *trial = alloc3(n);
    unsigned long long rs = 3;
    for (size_t i = 0; i < len; ++i) dv[i] = 0.05 * test_uniform(&rs, -1, 1);
    double E0 = problem_energy(pb, dv);
    problem_gradient(pb, dv, g);
    /* p = -s g with s large enough that the full step overshoots */
    double gg = vec_dot(len, g, g);
    double s = 1.0;
    for (;; s *= 4.0) {
        for (size_t i = 0; i < len; ++i) trial[i] = dv[i] - s * g[i];
        if (problem_energy(pb, trial) > E0 || s > 1e12) break;
    }
    for (size_t i = 0; i < len; ++i) p[i] = -s * g[i];
    double gTp = -s * gg;

    LineSearchOptions simple = {0, 60}, armijo = {1, 60};
    LineSearchResult rs_simple, rs_armijo;
    problem_energy(pb, dv);
    linesearch_backtrack(pb, dv, p, E0, gTp, &simple, dv_new, &rs_simple);
    CHECK(!rs_simple.stalled, "simple decrease finds a step");
    CHECK(rs_simple.alpha < 1.0, "the full step overshoots (alpha %.3g)", rs_simple.alpha);
    CHECK(rs_simple.energy <= E0, "accepted E %.12e <= E0 %.12e", rs_simple.energy, E0);
    double lg = log2(rs_simple.alpha);
    CHECK(fabs(lg - round(lg)) < 1e-12, "alpha is a power of 1/2 (%.6g)", rs_simple.alpha);
    CHECK(rs_simple.evals == (int)round(-lg) + 1, "one energy evaluation per trial (%d for alpha %.6g)",
          rs_simple.evals, rs_simple.alpha);
    /* the cache is at the accepted point */
    problem_gradient(pb, dv_new, g_cache);
    problem_energy(pb, dv_new);
    problem_gradient(pb, dv_new, g_fresh);
    double dg = 0;
    for (size_t i = 0; i < len; ++i) dg = fmax(dg, fabs(g_cache[i] - g_fresh[i]));
    CHECK(dg == 0.0, "gradient from the cache equals a fresh one (max diff %.3e)", dg);
    /* the trial before was rejected: E(dv + 2 alpha p) > E0 */
    for (size_t i = 0; i < len; ++i) trial[i] = dv[i] + 2.0 * rs_simple.alpha * p[i];
    CHECK(problem_energy(pb, trial) > E0, "the previous trial (alpha %.6g) was not a decrease", 2 * rs_simple.alpha);

    problem_energy(pb, dv);
    linesearch_backtrack(pb, dv, p, E0, gTp, &armijo, dv_new, &rs_armijo);
    CHECK(!rs_armijo.stalled, "Armijo finds a step");
    CHECK(rs_armijo.energy <= E0 + 1e-4 * rs_armijo.alpha * gTp, "Armijo: E %.12e <= %.12e", rs_armijo.energy,
          E0 + 1e-4 * rs_armijo.alpha * gTp);
    CHECK(rs_armijo.alpha <= rs_simple.alpha, "Armijo alpha %.6g <= simple alpha %.6g", rs_armijo.alpha,
          rs_simple.alpha);

    /* ascent: never accepted */
    for (size_t i = 0; i < len; ++i) p[i] = 1e-3 * g[i] / sqrt(gg);
    LineSearchOptions few = {0, 5};
    LineSearchResult r_up;
    problem_energy(pb, dv);
    linesearch_backtrack(pb, dv, p, E0 - 1e-12 * fabs(E0), 1e-3 * sqrt(gg), &few, dv_new, &r_up);
    CHECK(r_up.stalled, "an ascent direction stalls");
    CHECK(r_up.evals == 6 + 1, "6 trials and one re-evaluation at the start (%d)", r_up.evals);
    CHECK(r_up.energy == E0, "the cache is back at the starting point (E %.15e vs %.15e)", r_up.energy, E0);
    printf("line search along p = -s g, s = %.3g: simple alpha %.4g (%d evals), Armijo alpha %.4g\n",
           s, rs_simple.alpha, rs_simple.evals, rs_armijo.alpha);

    free(dv), free(g), free(p), free(dv_new), free(g_cache), free(g_fresh), free(trial);
    fixture_free(&f);
    return test_summary("test_linesearch");
}
