/* Stopping rules an outer method is handed (docs/design.md, "the one idea"), chosen
 * by the solver option `stop=NAME`:
 *  - "cn": the node-wise characteristic norm of SPEC 4 (HOT §5.2), s < eps
 *    with eps the run's --eps: the shared rule of the study;
 *  - "l2": the plain L2 norm of the projected gradient, ||g|| < tau (Gast et
 *    al. 2015 §7.1), tau from the option `tau` (default 1e-3, as in the HOT
 *    study's Gast15 runs).
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
    /* the same tolerance as a bound on the plain L2 norm ||g|| (what Gast et
     * al. 2015 §3.1's forcing term needs as tau_g) */
    double (*gradient_tolerance)(const StepProblem *pb, double tol);
} StopRuleOps;

int stop_rule_count(void);
const StopRuleOps *stop_rule_get(int i);
const StopRuleOps *stop_rule_find(const char *name);

#endif
