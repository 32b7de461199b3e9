/* Stopping rules an outer method is handed (docs/design.md, "the one idea"), chosen
 * by the solver option `stop=NAME`:
 *  - "cn": the node-wise characteristic norm of SPEC 4 (HOT §5.2), s < eps
 *    with eps the run's --eps: the shared rule of the study;
 *  - "l2": the plain L2 norm of the projected gradient, ||g|| < tau (Gast et
 *    al. 2015 §7.1), tau from the option `tau` (default 1e-3, as in the HOT
 *    study's Gast15 runs);
 *  - "decrement": the Newton-decrement estimate of the share of the step's
 *    energy decrease still to gain, d / (E_0 - E_k + d) < eps with
 *    d = -g^T p / 2 for the outer method's search direction p (SPEC 4.1).
 * A rule decides at the iterate (measure, before any direction is
 * computed) or on the search direction (direction_measure, after the
 * direction and before the line search); either may return INFINITY for
 * "never decides here", so an outer method calls both tests whatever its rule.
 * Whatever the rule, the residual recorded per iteration and per step is the
 * CN residual, so every solver is reported on one scale. A rule is one
 * measure function plus one line in the table of stop_rule.c. */
#ifndef MPM_STOP_RULE_H
#define MPM_STOP_RULE_H

#include "core/problem.h"

typedef struct {
    const char *name;
    const char *description;
    /* the option holding the tolerance and its default; NULL: the run's eps */
    const char *tol_key;
    double tol_default;
    /* the quantity compared with the tolerance; cn_residual is
     * problem_cn_residual(pb, g), already computed */
    double (*measure)(const StepProblem *pb, const double *g, double cn_residual);
    /* the quantity compared with the tolerance once the search direction p
     * at the iterate is known: gTp = g^T p (NAN when the direction is no
     * model minimiser, e.g. a steepest-descent fallback), E0 the energy at
     * the solve's first iterate, E at the current one */
    double (*direction_measure)(double gTp, double E0, double E);
    /* the same tolerance as a bound on the plain L2 norm ||g|| (what Gast et
     * al. 2015 §3.1's forcing term needs as tau_g) */
    double (*gradient_tolerance)(const StepProblem *pb, double tol);
} StopRuleOps;

/* The decrement rule's measure (SPEC 4.1), exposed for tests. */
double stop_decrement_measure(double gTp, double E0, double E);

int stop_rule_count(void);
const StopRuleOps *stop_rule_get(int i);
const StopRuleOps *stop_rule_find(const char *name);

#endif
